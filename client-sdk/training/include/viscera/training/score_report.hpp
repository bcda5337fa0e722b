#pragma once  // SPDX-License-Identifier: Apache-2.0
// The score of one performance: the metrics (docs/TRAINING.md gives each formula), each pass
// criterion with its value and threshold, and why it failed; as JSON and as a short Markdown
// summary for the trainee's record.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "viscera/protocol/messages.hpp"

namespace viscera::training {

struct Criterion {
  std::string name;  ///< what is checked, e.g. "peak force"
  double value = 0, limit = 0;
  std::string unit;
  bool passed = false;
  std::string why;  ///< when it failed: the reason in words
};

struct ScoreReport {
  std::string exercise, kind, scene, source;
  bool started = false, completed = false, passed = false;
  std::string ending;  ///< how it ended: completed, out of time, dropped, the recording ended, ...
  std::uint64_t start_tick = 0, end_tick = 0;
  double time_s = 0;  ///< from the start to completion, or to the end
  std::uint64_t samples = 0;  ///< forces of the instrument scored
  std::uint64_t samples_without_command = 0;  ///< of them, forces whose command was not seen (no tip position)
  std::uint64_t undecodable = 0;  ///< payloads that did not decode (skipped)
  double path_length_m = 0, peak_force_n = 0, mean_contact_force_n = 0, time_above_force_limit_s = 0, max_edge_strain = 0;
  /// The largest strain at the instrument the forces carried (tip_strain, schema 18)
  double max_tip_strain = 0;
  double longest_hold_s = 0;  ///< retraction, force drill
  std::uint32_t drops = 0;  ///< retraction: let go before the hold was complete
  std::optional<protocol::Vector3> mark_m, target_m;  ///< palpation
  std::optional<double> mark_distance_m;  ///< palpation: from the mark to the target region's surface (0 inside)
  // incision: over the commands with the cut button held and the tip below the surface
  std::optional<double> incision_length_m;  ///< the extent of the tip's path along the line
  double incision_deviation_m = 0;  ///< the tip's largest distance from the line, across it (horizontal)
  double incision_mean_depth_m = 0, incision_max_depth_m = 0;  ///< below the surface where the blade first touched
  /// The largest edge strain of the tissue the blade cut, just after it cut it (the forces'
  /// cut_edge_strain, schema 17): how far the tissue next to the cut was pulled
  double incision_cut_strain = 0;
  std::vector<Criterion> criteria;
  std::vector<std::string> failures;  ///< the failed criteria's reasons, most telling first
};

nlohmann::json to_json(const ScoreReport& r);
std::string to_markdown(const ScoreReport& r);

}  // namespace viscera::training
