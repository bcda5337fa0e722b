#pragma once  // SPDX-License-Identifier: Apache-2.0
// A training exercise (docs/TRAINING.md): the scene it runs on, the task, the limits a safe
// performance keeps and the thresholds that pass it. Read from a JSON exercise file; every error
// names the file and the field.
#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace viscera::training {

enum class ExerciseKind { palpation, retraction, force_drill, incision };

const char* kind_name(ExerciseKind k);

struct Exercise {
  std::string source;  ///< the file it was read from
  std::string name, description;
  ExerciseKind kind = ExerciseKind::palpation;
  std::string scene;  ///< the scene the server loads for it (a name in the server's scene directory)
  std::uint32_t instrument = 1;  ///< the trainee's instrument
  double time_limit_s = 120;  ///< from the scene's loading to completion
  double peak_force_limit_n = 4.0;  ///< the largest force on the tissue a safe performance stays under
  /// The tissue's strain at the instrument (the forces' tip_strain: principal stretch strain averaged
  /// within the scene's strain radius of where it touches) a safe performance stays under. Scored
  /// when the file sets it, or sets no strain limit at all (then 0.4).
  std::optional<double> tip_strain_limit = 0.4;
  /// The organ's largest edge strain |L - L0| / L0 a safe performance stays under (the forces'
  /// max_edge_strain): scored only when the file sets it. It grows as the mesh is refined.
  std::optional<double> edge_strain_limit;
  /// An incision's strain where the blade cut (the forces' cut_edge_strain): the file's
  /// edge_strain, or 0.5.
  double cut_strain_limit() const { return edge_strain_limit.value_or(0.5); }

  // palpation: find the region by touch and mark it (button 1 of the instrument's device)
  std::string target_region = "nodule";
  double mark_tolerance_m = 0.01;  ///< the mark's distance to the region's surface (0 inside it)

  // retraction: grasp, lift by lift_m (within lift_tolerance_m) and hold for hold_s
  double lift_m = 0.02, lift_tolerance_m = 0.005;

  // force drill: hold a force of target_force_n (within force_tolerance_n) for hold_s
  double target_force_n = 1.0, force_tolerance_n = 0.1;

  double hold_s = 5.0;  ///< retraction and force drill

  // incision: with a scalpel, cut along the line from incision_from to incision_to (x, y offsets
  // [m] from the centre of the top of the organ's box, as the scene state gives it) to depth_m
  // below the surface where the blade first touched, within the tolerances
  std::array<double, 2> incision_from{-0.025, 0.0}, incision_to{0.025, 0.0};
  double incision_depth_m = 0.01, depth_tolerance_m = 0.004, line_tolerance_m = 0.004, length_tolerance_m = 0.01;
};

/// Reads and checks an exercise file; throws common::InputError naming the file and field.
Exercise read_exercise_file(const std::string& path);
/// The same from JSON text (`source` names it in errors).
Exercise parse_exercise(const std::string& json_text, const std::string& source);

/// Button bit of the instrument's commands that marks a place (palpation), or makes a scalpel cut
/// (incision: the server's kCutButton).
inline constexpr std::uint32_t kMarkButton = 1u;

}  // namespace viscera::training
