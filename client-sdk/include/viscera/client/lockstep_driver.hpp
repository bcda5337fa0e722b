#pragma once  // SPDX-License-Identifier: Apache-2.0
// The driver's side of lockstep (viscera-server --lockstep, docs/RECORDING.md): sends the ticks
// (LockstepStep) and takes what each produced (LockstepResult), over DDS in the partition the
// server was started in. Reliable and keep-all both ways: steps run in the order sent, none lost.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "viscera/protocol/messages.hpp"

namespace viscera::client {

class LockstepDriver {
 public:
  LockstepDriver(std::uint32_t domain_id, const std::string& partition);
  ~LockstepDriver();
  /// Waits until a lockstep server reads the steps and this driver its results.
  bool wait_for_server(std::chrono::milliseconds timeout);
  void send(const protocol::LockstepStep& step);
  /// The next result, waiting up to `timeout`; results that do not verify are counted and skipped.
  std::optional<protocol::LockstepResult> next_result(std::chrono::milliseconds timeout);
  std::uint64_t rejected() const { return rejected_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::uint64_t rejected_ = 0;
};

}  // namespace viscera::client
