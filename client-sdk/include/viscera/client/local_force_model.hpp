#pragma once  // SPDX-License-Identifier: Apache-2.0
// Rendering the server's local contact model at the device rate (docs/HAPTICS.md section 2): between
// server updates and across network delay the client renders F(x) = F0 - K (x - x0), with x0 the
// tip position the server computed F0 for and K = -dF/dx, pushing only out of the tissue (along
// the contact normal), within the contact's friction cone where it has friction
// (Force::friction_mu: its tangential part at most mu times its normal part), and never beyond
// the device's force limit.
#include <limits>

#include "viscera/protocol/messages.hpp"

namespace viscera::client {

struct RenderedForce {
  protocol::Vector3 force{};
  bool clamped = false;  ///< limited to the device's maximum force
};

/// x0: the tip position of the command the force answers; x: the tip position now.
RenderedForce render_local_model(const protocol::Force& f, const protocol::Vector3& x0, const protocol::Vector3& x, double max_force_n);

/// How the rendered force goes when the server stops answering: it fades linearly to zero over
/// `fade_s`, starting when the newest model is `stale_after_s` old or when the application says
/// the server is gone (Client::server_state), whichever comes first. It never holds a force the
/// server no longer confirms, and never drops it at once (a hand pushing against it would lurch).
/// A model that arrives later fades the force back in at the same rate. After a jump (restart())
/// the force moves from what the hand felt to the new model's over `fade_in_s`.
struct FadePolicy {
  double stale_after_s = 0.25;  ///< the newest model this old means the server is not answering
  double fade_s = 0.25;  ///< from full force to none [s]
  /// After a jump: from the force the hand felt to the new model's [s]. Short, because a hand that
  /// holds a force pushes deeper while the force it feels lags: with 0.25 s from zero, a 0.5 N
  /// hold overshot to 1.6 N once the fade ended. The slew limit keeps even this ramp from steps.
  double fade_in_s = 0.1;
  /// A contact regained with more than this force [N] is a jump, not a touch (restart): a first
  /// touch at the 0.5 m/s tool speed limit on the scenes' 1000 N/m contact starts at 0.5 N at
  /// most in its first 1 ms tick.
  double contact_onset_n = 1.0;
};

/// Renders at the device rate from the newest local model. When a new model arrives the force
/// blends from the previous model to the new one over `blend_s` (linearly in time) instead of
/// jumping (docs/HAPTICS.md section 2), and is limited to the device's maximum afterwards.
class LocalForceRenderer {
 public:
  explicit LocalForceRenderer(double max_force_n, double blend_s = 0.003, FadePolicy fade = {})
      : max_force_(max_force_n), blend_(blend_s), fade_(fade) {}
  /// A new model: `f`, computed by the server for the tool at `x0`, arriving at time `t_s`.
  void update(const protocol::Force& f, const protocol::Vector3& x0, double t_s);
  /// The server is gone (from time `t_s`): the force fades out from then, if not already fading.
  void server_lost(double t_s);
  /// A jump the hand must not feel as a step (the organ reset, reloaded, paused or given another
  /// material; a contact regained with force): from `t_s` the force moves linearly from the one
  /// rendered last to the newest model's over `fade_in_s`, down as well as up.
  void restart(double t_s);
  /// The same from the next model's arrival (a claim: its first answer may come 0.1 s later, and
  /// a ramp begun at the claim would be over by then).
  void restart_at_next_model() { restart_pending_ = true; }
  /// The force to command at tool position `x` at time `t_s` (zero before the first model); the
  /// renderer keeps it, for a restart.
  RenderedForce render(const protocol::Vector3& x, double t_s);
  /// Seconds since the newest model arrived (infinite before the first).
  double model_age_s(double t_s) const;
  /// The factor (0-1) the force is rendered with at `t_s`: 1 while models come, then the fade.
  double gain(double t_s) const;

 private:
  struct Model {
    protocol::Force force;
    protocol::Vector3 x0{};
  };
  /// When the fade out starts (infinite while models come).
  double fade_start_s() const;
  double max_force_, blend_;
  FadePolicy fade_;
  bool has_new_ = false, has_old_ = false;
  Model new_, old_;
  double arrived_s_ = 0;
  double lost_s_ = std::numeric_limits<double>::infinity();  // server_lost() time
  double resume_s_ = 0, resume_gain_ = 1;  // a model after a fade: when it came, and the gain then
  protocol::Vector3 last_rendered_{};  // render()'s last force
  bool restart_pending_ = false;
  double jump_s_ = -1;  // the last restart (-1: none)
  protocol::Vector3 jump_from_{};  // the force rendered just before it
};

}  // namespace viscera::client
