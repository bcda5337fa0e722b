#include "viscera/recording/sequence_gaps.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::recording {

void SequenceGaps::add(std::uint64_t writer, std::uint64_t seq) {
  auto [it, fresh] = writers_.try_emplace(writer);
  Writer& w = it->second;
  ++w.received;
  if (fresh) {
    w.first = w.last = seq;
    return;
  }
  if (seq <= w.last) {
    ++w.out_of_order;
    if (w.pending.erase(seq) == 1) {  // a skipped number, come late: not lost after all
      --w.missing;
      const bool left = w.pending.count(seq - 1) > 0, right = w.pending.count(seq + 1) > 0;
      if (!left && !right) --w.gaps;  // its run is filled
      if (left && right) ++w.gaps;  // its run split in two
    }
    return;
  }
  if (seq > w.last + 1) {
    w.missing += seq - w.last - 1;
    ++w.gaps;
    for (std::uint64_t s = seq - 1; s > w.last && seq - s <= kLateWindow; --s) w.pending.insert(s);
  }
  w.last = seq;
  // Numbers further back than the window are lost for good: forget them.
  while (!w.pending.empty() && *w.pending.begin() + kLateWindow < seq) w.pending.erase(w.pending.begin());
}

std::uint64_t SequenceGaps::missing() const {
  std::uint64_t n = 0;
  for (const auto& [id, w] : writers_) n += w.missing;
  return n;
}

}  // namespace viscera::recording
