#pragma once  // SPDX-License-Identifier: Apache-2.0
// Scores a performance of an exercise from the session's streams (docs/TRAINING.md): the same
// class reads a live session (the trainer's stream tap) and a recording, so both give the same
// numbers. Forces are joined with the commands they answer (by instrument, client and sequence
// number: the tip position, the buttons) and processed in tick order, not arrival order; a live
// trainer processes what is a margin behind the newest tick, a recording everything at the end.
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscera/training/exercise.hpp"
#include "viscera/training/score_report.hpp"

namespace viscera::training {

class ExerciseScorer {
 public:
  explicit ExerciseScorer(Exercise exercise);

  /// A payload of a session stream; instrument commands, forces, events and the scene state are
  /// used, the rest ignored, undecodable payloads counted.
  void take(protocol::Stream stream, std::span<const std::uint8_t> payload);
  /// Processes the forces and events of ticks up to `tick` (live: a margin behind newest_tick()).
  void advance(std::uint64_t tick);
  /// Processes everything taken (a recording's end, or a live run's). `why` says why it ended
  /// before the exercise did (default: the instrument stopped; a trainer stopped by a signal says so).
  void finish(const std::string& why = "the instrument stopped before the time limit");

  /// Whether the exercise has started (its scene loaded) and ended (completed, or out of time).
  bool started() const { return start_tick_.has_value(); }
  bool ended() const { return ended_; }
  /// The newest tick of a force or server event taken.
  std::uint64_t newest_tick() const { return newest_tick_; }
  /// What happened since the last call, for the trainee and the instructor (live feedback).
  std::vector<std::string> take_feedback();
  ScoreReport report() const;

 private:
  struct Pending {
    std::uint64_t tick = 0;
    int order = 0;  ///< events before forces within a tick
    std::uint64_t n = 0;  ///< arrival number: ties keep arrival order
    std::optional<protocol::Force> force;
    std::optional<protocol::Event> event;
    bool operator<(const Pending& o) const { return std::tie(tick, order, n) < std::tie(o.tick, o.order, o.n); }
  };
  void process(const Pending& p);
  void process_event(const protocol::Event& e);
  void process_force(const protocol::Force& f, const std::optional<protocol::Command>& c);
  /// The instrument's commands from the last one walked to `c`, in their own order: the path
  /// length and the buttons' presses (forces of one tick echo commands out of order).
  /// `f`: the force being processed (its contact point is where a mark touches the tissue).
  void walk_commands(const protocol::Command& c, const protocol::Force& f);
  void end(std::uint64_t tick, bool completed, const std::string& how);
  double seconds(std::uint64_t from_tick, std::uint64_t to_tick) const;
  void say(std::string line);

  Exercise exercise_;
  std::vector<Pending> pending_;
  std::uint64_t arrivals_ = 0, newest_tick_ = 0;
  std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint64_t>, protocol::Command> commands_;  // by instrument, client, seq
  std::uint64_t undecodable_ = 0;
  double rate_hz_ = 0;
  std::optional<protocol::RegionInfo> target_;
  std::string scene_name_;
  std::optional<std::uint64_t> start_tick_;
  bool ended_ = false;
  std::vector<std::string> feedback_;
  ScoreReport r_;
  // Running state of the processed samples.
  std::optional<protocol::Vector3> last_tip_;  ///< of the newest command walked
  std::optional<std::pair<std::uint32_t, std::uint64_t>> walked_;  ///< client and seq of the newest command walked
  std::uint64_t last_tick_ = 0, last_above_tick_ = 0, contact_samples_ = 0;
  std::uint64_t tip_strain_samples_ = 0;  // forces in contact that carried a strain at the instrument (schema 18)
  double contact_force_sum_ = 0;
  std::optional<std::uint64_t> hold_start_;
  bool grasped_ = false;
  std::optional<double> grasp_z_;
  double announced_hold_s_ = 0;
  bool warned_force_ = false, warned_strain_ = false, warned_tip_strain_ = false;
  // incision
  void walk_incision(const protocol::Command& k, const protocol::Force& f);
  std::optional<protocol::Vector3> top_;  ///< centre of the top of the organ's box (scene state)
  std::optional<double> touch_z_, surface_z_;  ///< where the newest contact began (height); the surface where the cut began
  bool in_contact_ = false;
  bool cutting_ = false;
  std::uint64_t cut_samples_ = 0;  ///< commands with the blade below the surface
  double along_min_ = 0, along_max_ = 0, depth_sum_ = 0;
};

}  // namespace viscera::training
