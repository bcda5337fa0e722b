#pragma once  // SPDX-License-Identifier: Apache-2.0
// The table of streams: for each, its name (the DDS topic is "viscera_" + name), the FlatBuffers
// root table of its payloads, its QoS, and what the code that handles streams in general needs
// to know (is it state, may a sample be lost, how to check a payload). dds.cpp makes the topics
// and QoS from it; the recorder, the replay, the console and the SDK ask it instead of listing
// streams. A new stream is a value of `Stream` (dds.hpp), one row here, its schema and its
// message's encode/decode (messages.hpp), and a `Message` specialisation (typed_reader.hpp).
#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "viscera/protocol/dds.hpp"

namespace viscera::protocol {

enum class Reliability { best_effort, reliable };
enum class Durability { volatile_only, transient_local };

struct StreamInfo {
  Stream stream;
  const char* topic;  ///< "viscera_force_feedback"
  const char* schema;  ///< the payload's FlatBuffers root table, in namespace viscera.wire
  const char* schema_file;  ///< the protocol/schemas/*.fbs that defines it, without ".fbs"
  Reliability reliability;
  int depth;  ///< keep the last `depth` samples per key (source_id); 0: keep all
  Durability durability;
  /// The newest sample is the current state (the scene, its surface, its files): a late reader
  /// gets it at once (transient local), a replay republishes it after a seek, a recording keeps it.
  bool state;
  /// Written at the physics or device rate, where the next sample replaces a lost one: best effort,
  /// and a slow reader skips samples rather than holding the writer back.
  bool droppable;
  /// Part of a live session, so recorded and replayed; the lockstep streams are a re-simulation's own.
  bool session;
  /// Checks a payload as its receivers do (the stream's decode_*); `why` names what is wrong.
  bool (*verify)(std::span<const std::uint8_t> payload, std::string* why);
};

/// Every stream, in the order of `Stream`.
const std::array<StreamInfo, kStreamCount>& streams();
const StreamInfo& stream_info(Stream s);

}  // namespace viscera::protocol
