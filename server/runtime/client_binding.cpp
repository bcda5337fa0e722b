#include "viscera/runtime/client_binding.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <iterator>

namespace viscera::runtime {

bool ClientBinding::admit(std::uint32_t client_id, const Sender& from, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  // Ids whose holders went silent are forgotten once there are many: a participant that sprays ids
  // cannot grow the table without bound (each entry lives a lease at most once it is large; an
  // identity's id so forgotten may be taken by another, which needs 4096 ids in use at once).
  if (holders_.size() >= 4096)
    for (auto it = holders_.begin(); it != holders_.end();) it = now_ns - it->second.last_ns > lease_ns_ ? holders_.erase(it) : std::next(it);
  const auto [it, fresh] = holders_.try_emplace(client_id, Holder{from, now_ns});
  Holder& h = it->second;
  if (!fresh && h.sender.participant != from.participant) {
    if (by_identity_ && h.sender.identity != from.identity) return false;
    if (now_ns - h.last_ns <= lease_ns_) return false;
  }
  h = {from, now_ns};
  return true;
}

std::size_t ClientBinding::held() const {
  std::lock_guard lock(mutex_);
  return holders_.size();
}

}  // namespace viscera::runtime
