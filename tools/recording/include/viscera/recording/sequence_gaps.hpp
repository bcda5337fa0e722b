#pragma once
// Drops, counted and never hidden: every writer numbers its samples 1, 2, 3, ... (the envelope's
// seq), so the numbers a recorder did not receive between the first and the last it did are the
// samples it lost. Counted per writer; a number that comes again or late is counted apart (DDS
// delivers each writer's samples in order, so none is expected).
#include <cstdint>
#include <map>

namespace viscera::recording {

class SequenceGaps {
 public:
  struct Writer {
    std::uint64_t first = 0, last = 0;  ///< sequence numbers received first and highest
    std::uint64_t received = 0;
    std::uint64_t missing = 0;  ///< numbers skipped between first and last
    std::uint64_t gaps = 0;  ///< runs of skipped numbers
    std::uint64_t out_of_order = 0;  ///< numbers at or below the highest seen (repeats, late)
  };
  void add(std::uint64_t writer, std::uint64_t seq);
  const std::map<std::uint64_t, Writer>& writers() const { return writers_; }
  std::uint64_t missing() const;

 private:
  std::map<std::uint64_t, Writer> writers_;
};

}  // namespace viscera::recording
