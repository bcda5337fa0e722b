#pragma once  // SPDX-License-Identifier: Apache-2.0
// What waits to go to one browser, bounded, so that a slow browser never holds the bridge or the
// server back and never makes it grow: the newest mesh frame only (a frame not yet sent is
// replaced by the next one, counted as skipped), then messages in order up to a byte budget;
// over the budget the oldest droppable ones (forces, telemetry) go first, and if what is left
// still does not fit, the browser is too slow to keep and the caller closes it.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

namespace viscera::console {

struct OutMessage {
  std::shared_ptr<const std::string> data;  ///< shared between every browser that gets it
  bool binary = false;
  bool droppable = false;
};

class Outbox {
 public:
  explicit Outbox(std::size_t max_bytes) : max_bytes_(max_bytes) {}
  /// Offers the newest mesh frame (binary); replaces one still waiting.
  void put_frame(std::shared_ptr<const std::string> frame);
  /// Queues a message; false when it cannot be kept within the budget even after dropping every
  /// droppable one (the browser is too slow: close it).
  bool put(OutMessage m);
  /// The next message to send: queued messages first (their order kept), then the frame.
  std::optional<OutMessage> take();
  bool empty() const { return queue_.empty() && !frame_; }
  std::size_t queued_bytes() const { return bytes_ + (frame_ ? frame_->size() : 0); }
  std::uint64_t frames_skipped() const { return frames_skipped_; }
  std::uint64_t messages_dropped() const { return messages_dropped_; }

 private:
  std::size_t max_bytes_;
  std::deque<OutMessage> queue_;
  std::size_t bytes_ = 0;
  std::shared_ptr<const std::string> frame_;
  std::uint64_t frames_skipped_ = 0, messages_dropped_ = 0;
};

}  // namespace viscera::console
