#pragma once  // SPDX-License-Identifier: Apache-2.0
// How commands are answered: the command thread answers every command the moment it arrives with
// the reaction at the commanded pose on the newest published state (a Snapshot), so the round trip
// never waits for a physics step; the physics thread publishes a snapshot after every tick. The
// answer carries the local force model (docs/PROTOCOL.md, "The local force model"): the contact's
// force, point, normal and stiffness, the penalty in series with the tissue condensed onto it.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/contact_compliance.hpp"
#include "viscera/runtime/contact_proxy.hpp"
#include "viscera/runtime/grasp_hold.hpp"
#include "viscera/runtime/probe_contact.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace viscera::runtime {

/// The organ after a tick and the tissue each grasper holds; never changed once published.
struct Snapshot {
  std::uint64_t tick = 0;  ///< the tick after which it was taken
  double max_edge_strain = 0;  ///< the organ's largest edge strain that tick's force evaluations saw
  std::vector<Vec3> x;
  std::map<std::uint32_t, GraspHold> grasped;
  /// The scalpels pressed through the tissue (above the scene's cut force) and cutting
  std::set<std::uint32_t> pressed_through;
  /// The scalpels whose blade was in a cut after the tick: cutting, or leaving a cut
  /// (SimulatedTool::leaving_cut). A command that releases the cut button leaves the cut (the
  /// next tick says so): it touches nothing, as the blade did not.
  std::set<std::uint32_t> in_cut;
  /// Per instrument in contact: the tissue's strain at it after the tick (ContactResult::tip_strain)
  std::map<std::uint32_t, double> tip_strain;
  /// The organ's jumps so far (protocol::Force::organ_epoch)
  std::uint32_t organ_epoch = 0;
  /// A paused organ: a tip pressed deeper than the contact's depth limit still meets the surface
  /// it went in through (surface_exit.hpp, on the way back to where the tool is held: the tools
  /// do not move while paused), so a hand pressing on a frozen organ never falls through.
  bool paused = false;
  std::map<std::uint32_t, Vec3> tool_position;  ///< each active tool's, after the tick
  /// Each active tool's proxy after the tick: an answer tracks it to the commanded tip.
  std::map<std::uint32_t, ContactProxy> proxies;
  double tool_reach_m = 0;  ///< how far a tool may move in one tick (the scene's speed limit / rate)
};

/// The contact proxy of `spec` in `scene`: its tip, the scene's contact stiffness, dashpot,
/// friction and force limit.
ContactProxyParameters proxy_parameters(const SceneSpec& scene, const InstrumentSpec& spec);

/// Grasped tissue follows the jaws through stiff springs; the tool feels their reaction.
void add_grasp(ContactResult& result, const GraspHold::Reaction& reaction);

/// The local force model's stiffness: the contact's coupling in series with the tissue condensed
/// onto the contact: along the contact normal, and across it too where friction holds the tool
/// (a stuck proxy's coupling is isotropic); the coupling alone (an upper bound) until the
/// tissue's compliance at the contact is known; with `wait`, it waits for it (lockstep: the same
/// bits whenever the compliance worker is done).
std::array<double, 9> local_stiffness(const ContactResult& r, ContactCompliance& compliance, bool wait = false);

/// The force message answering `command` of `owner`'s instrument.
protocol::Force force_message(std::uint32_t instrument_id, std::uint32_t owner, const protocol::Command& command, const ContactResult& r,
                              const std::array<double, 9>& stiffness, std::int64_t server_stamp_ns, std::int64_t step_time_ns);

class CommandResponder {
 public:
  /// The instruments of a new organ: one contact query each (it keeps scratch space), on the
  /// organ's surface.
  void set_instruments(const std::vector<InstrumentSpec>& instruments, const std::shared_ptr<const ContactSurface>& surface,
                       double contact_stiffness_n_per_m);
  /// The organ's surface after a cut, for every query (the caller holds off the command thread).
  void set_surface(const std::shared_ptr<const ContactSurface>& surface);
  /// Physics thread, after each tick.
  void publish(std::shared_ptr<const Snapshot> snapshot);
  std::shared_ptr<const Snapshot> latest() const;
  /// Command thread: the reaction on `instrument_id` at the commanded pose on the newest snapshot,
  /// or as near it as the tool can be after the next tick (`used`, if given, gets that snapshot:
  /// its tick, strain and epoch go with the answer).
  ContactResult answer(std::uint32_t instrument_id, const protocol::Command& command, std::shared_ptr<const Snapshot>* used = nullptr) const;

 private:
  std::map<std::uint32_t, std::unique_ptr<ProbeContact>> queries_;
  std::set<std::uint32_t> scalpels_;
  mutable std::mutex mutex_;  // guards the snapshot pointer only
  std::shared_ptr<const Snapshot> snapshot_;
};

}  // namespace viscera::runtime
