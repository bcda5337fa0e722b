#include "viscera/protocol/binary_schemas.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <array>
#include <string_view>

#include "viscera/protocol/streams.hpp"

namespace viscera::protocol {

namespace detail {
// Generated (cmake/embed_binary_schemas.cmake), in the order of VISCERA_BFBS_SCHEMAS in
// protocol/CMakeLists.txt.
extern const std::span<const std::uint8_t> kBinarySchemas[];
}  // namespace detail

namespace {
// The schema files in the order of VISCERA_BFBS_SCHEMAS (protocol/CMakeLists.txt).
constexpr std::array<std::string_view, 10> kFiles{"instrument_command", "force_feedback", "session",     "telemetry", "surface_mesh",
                                                  "mesh_frame",         "event",          "scene_files", "lockstep",  "lockstep_result"};
}  // namespace

BinarySchema binary_schema(Stream s) {
  const StreamInfo& info = stream_info(s);
  const auto file = std::find(kFiles.begin(), kFiles.end(), info.schema_file);
  return {std::string("viscera.wire.") + info.schema, detail::kBinarySchemas[file - kFiles.begin()]};
}

}  // namespace viscera::protocol
