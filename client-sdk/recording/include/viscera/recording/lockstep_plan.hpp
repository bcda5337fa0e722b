#pragma once  // SPDX-License-Identifier: Apache-2.0
// What re-simulating a recorded session takes, read from the recording alone (no network): the
// lockstep steps that give a fresh server the recorded instrument commands and session requests
// at the ticks at which the original server applied them, and what each tick must reproduce.
//
// Where each input goes, from what the original server stamped (schema 7):
// - a force stepped at tick T (step_time_ns > 0) names the command its instrument stepped with:
//   that command is in step T's commands whenever it differs from the one stepped before;
// - a force answered at once on the state after tick T (step_time_ns = 0, tick T) is in step
//   T+1's answers;
// - a server event at tick T says a request took effect there: claims, releases (by the owner or
//   by the lease), pause, resume, reset become those requests in step T; a scene loaded, a
//   material or rate changed become the recorded request they name (request_seq); refusals
//   changed nothing and are left out;
// - a mesh frame stamped tick T asks step T for the surface.
// The recording must hold the scene's first tick onwards; a recorder that joined later starts the
// re-simulation at the scene's first tick with no inputs until its first (the notes say so).
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/recording/recording.hpp"

namespace viscera::recording {

/// A recorded force, as compared: all but the wall-clock stamps and the stiffness.
struct ExpectedForce {
  std::uint32_t instrument_id = 0, client_id = 0;
  std::uint64_t command_seq = 0;
  bool stepped = false;  ///< step_time_ns > 0 (else answered at once)
  bool in_contact = false;
  protocol::Vector3 force{}, torque{}, contact_point{}, contact_normal{};
  double penetration_m = 0;
  double max_edge_strain = 0;
  std::array<double, 9> stiffness{};
  std::uint64_t log_time_ns = 0;
  bool cutting = false;  ///< a scalpel's blade cutting (schema 17)
  double cut_edge_strain = 0;  ///< the largest edge strain of what it cut that tick (schema 17)
  double tip_strain = 0;  ///< the tissue's strain at the instrument (schema 18)
  std::uint32_t organ_epoch = 0;  ///< the organ's jumps so far (schema 19)
};

struct ExpectedEvent {
  protocol::EventKind kind{};
  std::uint32_t instrument_id = 0, client_id = 0;
  std::uint64_t request_seq = 0;
  double sim_time_s = 0;
};

/// A recorded surface frame: its simulated time and a digest of its positions (the positions are
/// read again from the recording only to name a divergence).
struct ExpectedFrame {
  double sim_time_s = 0;
  std::uint64_t digest = 0;  ///< FNV-1a of the positions' bytes
  std::size_t vertex_count = 0;
  std::uint64_t log_time_ns = 0;
  std::uint32_t topology_generation = 0;  ///< the surface's (cuts change it)
};

struct LockstepPlan {
  RecordedScene scene;  ///< the scene re-simulated (the first recorded)
  std::uint64_t first_tick = 0, last_tick = 0;
  double sim_time_s = 0;  ///< at the first tick's start
  std::map<std::uint64_t, protocol::LockstepStep> steps;  ///< ticks with inputs or a frame; the others are empty steps
  std::map<std::uint64_t, std::vector<ExpectedForce>> forces;  ///< by the tick of the result that reproduces them
  std::map<std::uint64_t, std::vector<ExpectedEvent>> events;
  std::map<std::uint64_t, ExpectedFrame> frames;
  std::uint64_t recorded_forces = 0, recorded_events = 0, recorded_frames = 0;
  std::vector<std::string> notes;  ///< what could not be reproduced, and why
  bool strain_recorded = true;  ///< forces carry the organ's edge strain (recorded with schema 8 or later)
  bool cutting_recorded = true;  ///< forces say whether a blade cut (recorded with schema 17 or later)
  bool tip_strain_recorded = true;  ///< forces carry the strain at the instrument (recorded with schema 18 or later)
  bool organ_epoch_recorded = true;  ///< forces carry the organ's epoch (recorded with schema 19 or later)
  /// The step of `tick` (an empty one where nothing happens).
  protocol::LockstepStep step(std::uint64_t tick) const;
};

/// Reads the whole recording once. Throws common::InputError naming the file when it holds no
/// scene files (nothing to re-simulate) or no tick-stamped messages (recorded by a server older
/// than schema 7).
LockstepPlan make_lockstep_plan(Recording& recording);

/// FNV-1a (64 bits) of bytes: the frames' digest.
std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t h = 0xcbf29ce484222325ull);

}  // namespace viscera::recording
