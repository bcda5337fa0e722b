// recover(): a complete, indexed copy of every intact record of an MCAP file (McapReader::salvage_data  // SPDX-License-Identifier: Apache-2.0
// walks it, McapWriter writes the copy).
#include <map>

#include "viscera/common/input_error.hpp"
#include "viscera/common/same_file.hpp"
#include "viscera/mcap/mcap_reader.hpp"
#include "viscera/mcap/mcap_writer.hpp"

namespace viscera::mcap {

DataEnd recover(const std::string& in, const std::string& out, const std::string& compression) {
  if (common::same_file(in, out))
    throw common::InputError(out, 0, "", "is the file to recover (the same file by device and inode): write the recovered copy to another file");
  McapReader reader(in);
  WriterOptions options;
  options.profile = reader.profile();
  options.library = reader.library();
  options.compression = compression;
  options.chunk_ns = ~std::uint64_t{0};  // chunks by size only: log times may be far apart
  options.replace = false;  // the copy goes to a new file: never over another recording
  McapWriter writer(out, options);
  std::map<std::uint16_t, std::uint16_t> schema_id, channel_id;  // old -> new
  DataVisitor v;
  v.schema = [&](const Schema& s) { schema_id[s.id] = writer.add_schema(s.name, s.encoding, s.data); };
  v.channel = [&](const Channel& c) {
    channel_id[c.id] = writer.add_channel(c.schema_id ? schema_id.at(c.schema_id) : 0, c.topic, c.message_encoding, c.metadata);
  };
  v.message = [&](const Message& m) { writer.add_message(channel_id.at(m.channel_id), m.sequence, m.log_time, m.publish_time, m.data); };
  v.attachment = [&](const Attachment& a) { writer.add_attachment(a); };
  v.metadata = [&](const Metadata& m) { writer.add_metadata(m); };
  DataEnd end = reader.salvage_data(v);
  writer.close();
  return end;
}

}  // namespace viscera::mcap
