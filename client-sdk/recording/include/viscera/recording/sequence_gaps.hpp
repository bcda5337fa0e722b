#pragma once  // SPDX-License-Identifier: Apache-2.0
// Drops, counted and never hidden: every writer numbers its samples 1, 2, 3, ... (the envelope's
// seq), so the numbers a recorder did not receive between the first and the last it did are the
// samples it lost. Counted per writer. DDS keeps each instance's (key's) samples in order, but a
// take may hand over two instances of one writer interleaved, so a number may come just after a
// higher one: it is counted out of order and, if it was counted missing, no longer missing
// (numbers up to kLateWindow behind the highest are remembered for this).
#include <cstdint>
#include <map>
#include <set>

namespace viscera::recording {

class SequenceGaps {
 public:
  static constexpr std::uint64_t kLateWindow = 4096;
  struct Writer {
    std::uint64_t first = 0, last = 0;  ///< sequence numbers received first and highest
    std::uint64_t received = 0;
    std::uint64_t missing = 0;  ///< numbers skipped between first and last
    std::uint64_t gaps = 0;  ///< runs of skipped numbers
    std::uint64_t out_of_order = 0;  ///< numbers at or below the highest seen (repeats, late)
    std::set<std::uint64_t> pending;  ///< skipped numbers within kLateWindow of the highest
  };
  void add(std::uint64_t writer, std::uint64_t seq);
  const std::map<std::uint64_t, Writer>& writers() const { return writers_; }
  std::uint64_t missing() const;

 private:
  std::map<std::uint64_t, Writer> writers_;
};

}  // namespace viscera::recording
