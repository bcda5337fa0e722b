#pragma once  // SPDX-License-Identifier: Apache-2.0
// The MCAP container format (mcap.dev, "MCAP Format Specification", major version 0): the records
// viscera writes and reads, as plain structs. A file is the magic, a Header, the data section
// (schemas, channels and messages inside chunks; attachments and metadata beside them; a message
// index after each chunk; Data End), the summary section (schemas, channels, statistics, chunk,
// attachment and metadata indexes), the summary offsets, the Footer and the magic again. Every
// integer is little-endian; strings and byte arrays carry a uint32 length (a chunk's records and an
// attachment's data a uint64 one).
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace viscera::mcap {

inline constexpr std::array<std::uint8_t, 8> kMagic{0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum class Opcode : std::uint8_t {
  header = 0x01,
  footer = 0x02,
  schema = 0x03,
  channel = 0x04,
  message = 0x05,
  chunk = 0x06,
  message_index = 0x07,
  chunk_index = 0x08,
  attachment = 0x09,
  attachment_index = 0x0A,
  statistics = 0x0B,
  metadata = 0x0C,
  metadata_index = 0x0D,
  summary_offset = 0x0E,
  data_end = 0x0F,
};

struct Schema {
  std::uint16_t id = 0;
  std::string name, encoding;
  std::vector<std::uint8_t> data;
};

struct Channel {
  std::uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  std::map<std::string, std::string> metadata;
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0, publish_time = 0;  ///< [ns]
  std::vector<std::uint8_t> data;
};

struct Attachment {
  std::uint64_t log_time = 0, create_time = 0;  ///< [ns]
  std::string name, media_type;
  std::vector<std::uint8_t> data;
};

struct Metadata {
  std::string name;
  std::map<std::string, std::string> values;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
  std::uint64_t message_start_time = 0, message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

/// CRC-32 (IEEE 802.3, as zlib), the checksum MCAP uses: crc32_update(kCrc32Init, ...) then
/// crc32_final.
inline constexpr std::uint32_t kCrc32Init = 0xFFFFFFFFu;
std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t size);
inline std::uint32_t crc32_final(std::uint32_t crc) { return crc ^ 0xFFFFFFFFu; }
inline std::uint32_t crc32(const std::uint8_t* data, std::size_t size) { return crc32_final(crc32_update(kCrc32Init, data, size)); }

}  // namespace viscera::mcap
