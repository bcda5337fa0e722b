#include "viscera/console/outbox.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <utility>

namespace viscera::console {

void Outbox::put_frame(std::shared_ptr<const std::string> frame) {
  if (frame_) ++frames_skipped_;
  frame_ = std::move(frame);
}

bool Outbox::put(OutMessage m) {
  const std::size_t size = m.data ? m.data->size() : 0;
  // Drop the oldest droppable messages until the new one fits.
  for (auto it = queue_.begin(); bytes_ + size > max_bytes_ && it != queue_.end();) {
    if (it->droppable) {
      bytes_ -= it->data->size();
      it = queue_.erase(it);
      ++messages_dropped_;
    } else {
      ++it;
    }
  }
  if (bytes_ + size > max_bytes_) {
    if (m.droppable) {
      ++messages_dropped_;
      return true;
    }
    return false;
  }
  bytes_ += size;
  queue_.push_back(std::move(m));
  return true;
}

std::optional<OutMessage> Outbox::take() {
  if (!queue_.empty()) {
    OutMessage m = std::move(queue_.front());
    queue_.pop_front();
    bytes_ -= m.data->size();
    return m;
  }
  if (frame_) return OutMessage{std::exchange(frame_, nullptr), true, true};
  return std::nullopt;
}

}  // namespace viscera::console
