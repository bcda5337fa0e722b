#pragma once  // SPDX-License-Identifier: Apache-2.0
// One instrument as the physics thread moves it (docs/SCENE.md, "Simulated tools"): the tool follows
// its owner's newest commanded tip at most at the scene's speed limit in simulated time, so a
// server slower than real time (or a jumping device) never drives it through the tissue in one
// tick; a grasper's jaws grasp the tissue when they close and let go when they open, with
// hysteresis; and contact starts and ends with hysteresis, so a tool that bounces on the surface
// makes one contact. Pure state and logic on simulated time: no clock, no DDS.
#include <Eigen/Geometry>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/grasp_hold.hpp"
#include "viscera/runtime/probe_contact.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace viscera::runtime {

/// Jaws closing below this opening grasp; the grasp holds until they open above the second (a
/// device's jaw sensor jitters by a few hundredths of a radian).
inline constexpr double kJawGraspBelowRad = 0.1;
inline constexpr double kJawReleaseAboveRad = 0.2;
/// A contact ends after this much simulated time without touching (a tool bouncing on the surface
/// a few milliseconds apart is one contact).
inline constexpr double kContactEndAfterS = 0.05;

/// What changed in a tick, for the session's events.
enum class ToolEvent { none, grasped, let_go, contact_started, contact_ended };

/// Whether `command` makes the instrument cut: a scalpel with kCutButton held.
inline bool blade_cuts(const InstrumentSpec& spec, const protocol::Command& command) {
  return spec.kind == InstrumentKind::scalpel && (command.buttons & kCutButton) != 0;
}

/// A scalpel presses through the tissue (docs/CUTTING.md, "Cutting above a contact force") when
/// its contact force reaches the scene's cut force; it stays through until its tip is a tip
/// radius above the plane of the surface where it entered.
struct PressThrough {
  bool through = false;
  Vec3 entry_point = Vec3::Zero(), entry_normal = Vec3::UnitZ();  ///< where it entered, the normal out of the tissue
};

class SimulatedTool {
 public:
  explicit SimulatedTool(const InstrumentSpec& spec) : spec_(spec) {}

  const InstrumentSpec& spec() const { return spec_; }
  bool active() const { return active_; }
  const protocol::Command& command() const { return command_; }
  std::uint32_t owner() const { return owner_; }
  const Vec3& position() const { return position_; }
  const Vec3& velocity() const { return velocity_; }
  Eigen::Quaterniond orientation() const;
  const GraspHold& held() const { return held_; }
  /// A scalpel whose owner holds the cut button: its blade passes through the tissue, cutting,
  /// and its tip does not push it (blade_cuts()).
  bool cutting() const { return active_ && (blade_cuts(spec_, command_) || press_.through); }
  /// A scalpel of a scene with a cut force, pressed through the tissue (PressThrough).
  bool pressed_through() const { return active_ && press_.through; }
  /// A scalpel whose cut button was released: its blade may still be in the tissue, and it leaves
  /// the cut touching nothing until it is clear of the tissue (clear_of_tissue()), so releasing
  /// the button with the blade 12 mm deep does not put the whole depth on the contact at once.
  bool leaving_cut() const { return active_ && leaving_; }
  /// The blade is clear of the tissue: it touches as any tool from now on.
  void clear_of_tissue() { leaving_ = false; }
  /// After a tick: a scalpel of a scene with a cut force presses through when `contact`'s force
  /// reaches it, and comes out when its tip is back above the entry surface (PressThrough).
  void update_press_through(const ContactResult& contact);

  /// The tick's command (the newest of its owner), or inactive: an instrument without an owner or
  /// command exerts nothing, and a grasper lets go. A tool that becomes active starts at its
  /// commanded tip; returns true in that tick.
  bool begin_tick(bool active, std::uint32_t owner, const protocol::Command& command);
  /// Moves the tool by `offset` [m] at once, at rest: a tool that appears inside the tissue is
  /// withdrawn to its surface and enters at the speed limit.
  void withdraw(const Vec3& offset) {
    position_ += offset;
    velocity_ = Vec3::Zero();
    press_ = {};
  }
  /// Moves toward the commanded tip by at most `max_speed_m_s` x `dt_s`.
  void move(double dt_s, double max_speed_m_s);
  /// A grasper closes on the surface nodes of `surface` within its grasp radius when its jaws close
  /// below kJawGraspBelowRad, and lets go when they open above kJawReleaseAboveRad.
  ToolEvent update_grasp(std::span<const std::int32_t> surface, std::span<const Vec3> x, double grasp_stiffness_n_per_m);
  /// Lets go of whatever is held (organ reset, instrument released).
  void let_go() { held_ = {}; }
  /// Contact with hysteresis at simulated time `sim_time_s`, from whether the tool touched in the tick.
  ToolEvent update_contact(bool touching, double sim_time_s);

 private:
  InstrumentSpec spec_;
  bool active_ = false;
  std::uint32_t owner_ = 0;
  protocol::Command command_;
  Vec3 position_ = Vec3::Zero();
  Vec3 velocity_ = Vec3::Zero();  // over the current tick [m/s]
  GraspHold held_;
  PressThrough press_;
  bool leaving_ = false;
  bool touching_ = false;
  double last_touch_s_ = 0;
};

}  // namespace viscera::runtime
