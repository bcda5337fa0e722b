#include "viscera/mcap/integrity.hpp"  // SPDX-License-Identifier: Apache-2.0

#include "viscera/common/input_error.hpp"

namespace viscera::mcap {

Integrity check_integrity(McapReader& reader) {
  Integrity out;
  out.data = reader.salvage_data({});
  for (const auto& d : out.data.damaged)
    out.problems.push_back("bytes " + std::to_string(d.offset) + " to " + std::to_string(d.offset + d.length) + " of the data section: " + d.what);
  if (!out.data.complete && out.data.damaged.empty()) out.problems.push_back("the data section has no Data End: " + out.data.error);
  std::optional<Summary> summary;
  try {
    summary = reader.summary();
  } catch (const common::InputError& e) {
    out.problems.push_back(e.what());
    return out;
  }
  if (!summary) {
    out.problems.push_back("no summary (cut short: viscera-record recover makes it whole)");
    return out;
  }
  const auto each = [&](auto&& read) {
    try {
      read();
    } catch (const common::InputError& e) {
      out.problems.push_back(e.what());
    }
  };
  for (const auto& c : summary->chunks) each([&] { reader.read_chunk(c); });
  for (const auto& a : summary->attachments) each([&] { reader.read_attachment(a); });
  for (const auto& m : summary->metadata) each([&] { reader.read_metadata(m); });
  if (summary->statistics && out.data.damaged.empty() && summary->statistics->message_count != out.data.messages)
    out.problems.push_back("the statistics count " + std::to_string(summary->statistics->message_count) + " messages, the data section holds " +
                           std::to_string(out.data.messages));
  return out;
}

}  // namespace viscera::mcap
