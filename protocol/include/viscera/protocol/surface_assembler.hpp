#pragma once  // SPDX-License-Identifier: Apache-2.0
// Whole surfaces from the SurfaceTopology stream (schema 16): after a cut the server sends a patch
// of the surface before it, bounded by what the cut changed, and a whole surface every few
// patches. A reader keeps the whole surface and applies each patch to it, so that it always holds
// a whole surface of the generation its frames name.
#include <cstdint>
#include <optional>

#include "viscera/protocol/messages.hpp"

namespace viscera::protocol {

/// The whole surface that `patch` makes of `base` (surface_mesh.fbs says how). Throws
/// std::invalid_argument naming what does not fit: another mesh or base generation, an index
/// beyond the base, a kept triangle on a removed vertex, a vertex count that does not add up.
SurfaceTopology apply_surface_patch(const SurfaceTopology& base, const SurfaceTopology& patch);

class SurfaceAssembler {
 public:
  /// One message of the stream. A whole surface replaces the one held; a patch applies to the
  /// surface held when that is its base, and is otherwise skipped (a reader that joined late
  /// waits for the next whole surface). True when the surface held changed.
  bool take(const SurfaceTopology& message);
  /// The whole surface held, if any.
  const std::optional<SurfaceTopology>& surface() const { return surface_; }
  /// Patches that did not apply (their base not held, or not fitting it).
  std::uint64_t patches_skipped() const { return skipped_; }

 private:
  std::optional<SurfaceTopology> surface_;
  std::uint64_t skipped_ = 0;
};

}  // namespace viscera::protocol
