#include "viscera/recording/sequence_gaps.hpp"

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
    return;
  }
  if (seq > w.last + 1) {
    w.missing += seq - w.last - 1;
    ++w.gaps;
  }
  w.last = seq;
}

std::uint64_t SequenceGaps::missing() const {
  std::uint64_t n = 0;
  for (const auto& [id, w] : writers_) n += w.missing;
  return n;
}

}  // namespace viscera::recording
