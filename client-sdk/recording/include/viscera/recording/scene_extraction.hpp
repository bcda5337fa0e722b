#pragma once  // SPDX-License-Identifier: Apache-2.0
// The scenes of a recording back on disk, so a server can load them again: each recorded scene's
// mesh and material from its attachments (checked against their SHA-256), and its scene file
// with organ.mesh and organ.material pointing at them, named by the scene's own name (what
// load_scene asks for). Or, for a what-if re-simulation, a scene file from disk in place of the
// first recorded one: it must be the same organ (mesh, scale, refinement, fixed slab, instruments);
// its material, model, damping or contact may differ, and the differences are listed.
#include <optional>
#include <string>
#include <vector>

#include "viscera/recording/recording.hpp"

namespace viscera::recording {

struct ExtractedScenes {
  std::string scene_dir;  ///< every recorded scene, as <name>.json
  std::string first_scene;  ///< the scene to start the server with
  std::vector<std::string> differences;  ///< what the replacement scene changes ("organ.material: ...")
};

/// Writes into `dir` (created). `replacement`: a scene file used in place of the first recorded
/// one. Throws common::InputError naming the recording (an attachment missing or not matching its
/// digest) or the replacement file (unreadable, or another organ than the recording's).
ExtractedScenes extract_scenes(Recording& recording, const std::string& dir, const std::optional<std::string>& replacement = std::nullopt);

}  // namespace viscera::recording
