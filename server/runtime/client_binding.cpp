#include "viscera/runtime/client_binding.hpp"

#include <iterator>

namespace viscera::runtime {

bool ClientBinding::admit(std::uint32_t client_id, std::uint64_t participant, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  // Ids whose holders went silent are forgotten once there are many: a participant that sprays ids
  // cannot grow the table without bound (each entry lives a lease at most once it is large).
  if (holders_.size() >= 4096)
    for (auto it = holders_.begin(); it != holders_.end();) it = now_ns - it->second.last_ns > lease_ns_ ? holders_.erase(it) : std::next(it);
  const auto [it, fresh] = holders_.try_emplace(client_id, Holder{participant, now_ns});
  Holder& h = it->second;
  if (!fresh && h.participant != participant && now_ns - h.last_ns <= lease_ns_) return false;
  h = {participant, now_ns};
  return true;
}

std::size_t ClientBinding::held() const {
  std::lock_guard lock(mutex_);
  return holders_.size();
}

}  // namespace viscera::runtime
