#pragma once
// Rendering the server's local contact model at the device rate (HAPTICS.md section 2): between
// server updates and across network delay the client renders F(x) = F0 - K (x - x0), with x0 the
// tip position the server computed F0 for and K = -dF/dx, pushing only out of the tissue (along
// the contact normal) and never beyond the device's force limit.
#include "viscera/protocol/messages.hpp"

namespace viscera::client {

struct RenderedForce {
  protocol::Vector3 force{};
  bool clamped = false;  ///< limited to the device's maximum force
};

/// x0: the tip position of the command the force answers; x: the tip position now.
RenderedForce render_local_model(const protocol::Force& f, const protocol::Vector3& x0, const protocol::Vector3& x,
                                 double max_force_n);

/// Renders at the device rate from the newest local model. When a new model arrives the force
/// blends from the previous model to the new one over `blend_s` (linearly in time) instead of
/// jumping (HAPTICS.md section 2), and is limited to the device's maximum afterwards.
class LocalForceRenderer {
 public:
  explicit LocalForceRenderer(double max_force_n, double blend_s = 0.003) : max_force_(max_force_n), blend_(blend_s) {}
  /// A new model: `f`, computed by the server for the tool at `x0`, arriving at time `t_s`.
  void update(const protocol::Force& f, const protocol::Vector3& x0, double t_s);
  /// The force to command at tool position `x` at time `t_s` (zero before the first model).
  RenderedForce render(const protocol::Vector3& x, double t_s) const;
  /// Seconds since the newest model arrived (infinite before the first).
  double model_age_s(double t_s) const;

 private:
  struct Model {
    protocol::Force force;
    protocol::Vector3 x0{};
  };
  double max_force_, blend_;
  bool has_new_ = false, has_old_ = false;
  Model new_, old_;
  double arrived_s_ = 0;
};

}  // namespace viscera::client
