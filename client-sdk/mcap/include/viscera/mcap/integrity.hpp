#pragma once  // SPDX-License-Identifier: Apache-2.0
// The one judgement of an MCAP file's integrity that every tool shares (viscera-record info
// --verify, recover): every record of the data section parses and its CRC holds, the summary reads,
// and every chunk, attachment and metadata record its indexes point to reads and checks.
#include <cstdint>
#include <string>
#include <vector>

#include "viscera/mcap/mcap_reader.hpp"

namespace viscera::mcap {

struct Integrity {
  DataEnd data;  ///< the walk of the data section past damage (McapReader::salvage_data)
  std::vector<std::string> problems;  ///< one line each, naming the byte; empty: the file is intact
  bool intact() const { return problems.empty(); }
};

Integrity check_integrity(McapReader& reader);

}  // namespace viscera::mcap
