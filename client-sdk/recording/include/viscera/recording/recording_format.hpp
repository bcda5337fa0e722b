#pragma once  // SPDX-License-Identifier: Apache-2.0
// How viscera lays a session out in MCAP (docs/RECORDING.md), shared by the recorder, the
// replayer and the trainer:
// - a channel per (stream, writer, key): topic = the DDS topic, message encoding "flatbuffer",
//   schema = the stream's binary FlatBuffers schema (name = the root table, encoding
//   "flatbuffer"); channel metadata: "stream", "source_id" (the envelope's key), "writer" (the
//   writer's number in the recording, 1, 2, ...) and "partition";
// - a message = the payload as it was on the wire; sequence = the envelope's seq (per writer);
//   log time = when the recorder received it [ns since the Unix epoch, never decreasing];
//   publish time = the envelope's stamp (the writer's clock, ns since the Unix epoch);
// - metadata "viscera.recording" first (schema version, domain, partition, streams, recorder),
//   one "viscera.scene" per scene files received (server build and settings, first tick,
//   simulated time, each file's attachment name and SHA-256), "viscera.drops" last (each
//   writer's gaps);
// - attachments: each file a scene was built from, once per content, named "<role>/<file name>"
//   (role scene, mesh or material).
#include <cstdint>
#include <string>

namespace viscera::recording {

inline constexpr const char* kMessageEncoding = "flatbuffer";
inline constexpr const char* kSchemaEncoding = "flatbuffer";
inline constexpr const char* kRecordingMetadata = "viscera.recording";
inline constexpr const char* kSceneMetadata = "viscera.scene";
inline constexpr const char* kDropsMetadata = "viscera.drops";

/// The attachment that holds a scene's file: "mesh/liver2.msh".
std::string attachment_name(const std::string& role, const std::string& path);

}  // namespace viscera::recording
