#pragma once  // SPDX-License-Identifier: Apache-2.0
// What a haptic device's loop does each period, as a state machine with no clock and no network
// of its own: the caller tells it the time, the server's state and (every 0.1 s) what the scene
// state says of the instrument, and it says what to do this period. It holds the local force
// renderer, so that every way the loop can lose the server or the instrument fades the force the
// hand feels instead of cutting it. run_device (device_runner.hpp) drives it with a real device
// and a Client; tests drive it with invented times and states.
//
//   driving ──server gone──▶ fading (commands still sent) ──force at 0──▶ end (exit 4)
//                                                         └─ reconnect ─▶ waiting ──server back──▶ claim again ─▶ driving
//   driving ──another client owns it──▶ standing by (nothing sent, force fades) ──handed back──▶ driving
//   driving ──the scene shows it free (released for silence, or under this client id)──▶ fading, nothing sent ──force at 0──▶ end (exit 5)
//                                                                                                       └─ reconnect ─▶ claim again (every 1 s until
//                                                                                                       it holds) ─▶ driving
//   driving ──a new scene was loaded──▶ claim again ─▶ driving
//   after every claim that holds, every jump of the organ (its epoch) and every contact regained
//   with force, the force ramps from what the hand felt to the new one; ForceSlewLimit bounds its
//   change per period besides.
#include <cstdint>
#include <optional>
#include <string>

#include "viscera/client/client.hpp"
#include "viscera/client/local_force_model.hpp"

namespace viscera::client {

struct DeviceLoopOptions {
  std::uint32_t client_id = 1, instrument = 1;
  double max_force_n = 15, blend_s = 0.003;
  FadePolicy fade;
  /// After the server is gone and the force has faded, wait for one to come back; after the
  /// instrument was freed under this client (the server's lease ran out during a stall of this
  /// process), claim it again once the force has faded.
  bool reconnect = false;
  /// The largest change of the force on the hand per millisecond [N/ms] (ForceSlewLimit; the
  /// default is argued in docs/FAULTS.md); infinite: no limit.
  double slew_n_per_ms = 1.0;
};

/// What the scene state says, when the loop looks (every 0.1 s while the server is there).
struct InstrumentView {
  std::uint32_t generation = 0;  ///< the scene's generation (a new one: a scene was loaded)
  std::uint32_t owner = 0;  ///< the instrument's owner (0: free)
  std::string scene;  ///< the scene's name
};

class DeviceLoop {
 public:
  enum class Action {
    drive,  ///< read the device, send the tip, render the newest model
    render_only,  ///< send nothing; render the fading force at the last tip
    claim_again,  ///< claim the instrument again (a new scene, a server back, an instrument freed), then call claimed()
    end,  ///< the run is over (lost() or instrument_lost_t_s() say why)
  };
  struct Step {
    Action action = Action::drive;
    bool end_after = false;  ///< render_only: this period's render is the last (the force reached zero)
    std::string note;  ///< a line for the user ("" : none), "t = 1.23 s  ..."
  };

  DeviceLoop(const DeviceLoopOptions& options, std::uint32_t generation);
  /// Whether the loop wants to look at the scene state at `t_s` (every 0.1 s while the server is there).
  bool scene_check_due(double t_s) const;
  /// The start of a period at `t_s`: the server's state, and the scene if it was looked at.
  Step next(double t_s, ServerState server, const std::optional<InstrumentView>& scene);
  /// After Action::claim_again: whether the claim held (`why` if not) and the scene now. After a
  /// claim that holds, the force ramps to the first answer's (LocalForceRenderer::restart).
  std::string claimed(double t_s, bool ok, const std::string& why, const InstrumentView& now);
  /// A force from the server at `t_s` with the organ's epoch `epoch` (protocol::Force): when the
  /// organ jumped since the last one (a reset, a scene or material loaded, a pause or a resume),
  /// the force ramps from what the hand felt to the new one; returns a note then.
  std::string organ_epoch(double t_s, std::uint32_t epoch);

  LocalForceRenderer& renderer() { return renderer_; }
  bool standing_by() const { return standing_by_; }
  bool lost() const { return lost_; }  ///< ended because the server was gone
  double server_lost_t_s() const { return server_lost_t_; }  ///< -1: never
  double faded_t_s() const { return faded_t_; }  ///< when the force reached zero after a loss (-1: never)
  /// When the instrument was shown free under this client, if it was not claimed again since (-1: never).
  double instrument_lost_t_s() const { return instrument_lost_t_; }
  int instrument_losses() const { return instrument_losses_; }  ///< how often the instrument was shown free under this client
  /// The longest gap between two periods longer than the server's lease (this process did not
  /// run), and when the last such gap ended (0 and -1: none).
  double stall_s() const { return stall_s_; }
  double stall_end_t_s() const { return stall_end_t_; }
  int server_returns() const { return server_returns_; }
  int taken_over() const { return taken_over_; }

 private:
  enum class Claim { none, scene_loaded, server_back, instrument_free };
  static constexpr double kRetryS = 1.0;  ///< [s] between claims of an instrument freed under this client
  DeviceLoopOptions o_;
  LocalForceRenderer renderer_;
  std::uint32_t generation_;
  Claim pending_ = Claim::none;
  bool standing_by_ = false, lost_ = false;
  double server_lost_t_ = -1, faded_t_ = -1, instrument_lost_t_ = -1, last_scene_check_ = 0, retry_t_ = 0;
  double last_t_ = -1, stall_s_ = 0, stall_end_t_ = -1;
  int server_returns_ = 0, taken_over_ = 0, instrument_losses_ = 0;
  std::optional<std::uint32_t> epoch_;
};

}  // namespace viscera::client
