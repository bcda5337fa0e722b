#include "viscera/client/lockstep_driver.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <deque>
#include <thread>

#include "viscera/protocol/dds.hpp"

namespace viscera::client {

namespace proto = viscera::protocol;

struct LockstepDriver::Impl {
  proto::Participant participant;
  proto::Writer steps;
  proto::Reader results;
  std::deque<proto::LockstepResult> ready;
  Impl(std::uint32_t domain, const std::string& partition)
      : participant(domain, partition), steps(participant, proto::Stream::lockstep_step), results(participant, proto::Stream::lockstep_result) {}
};

LockstepDriver::LockstepDriver(std::uint32_t domain_id, const std::string& partition) : impl_(std::make_unique<Impl>(domain_id, partition)) {}
LockstepDriver::~LockstepDriver() = default;

bool LockstepDriver::wait_for_server(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  if (!impl_->steps.wait_for_readers(timeout)) return false;
  while (impl_->results.alive_writers() == 0) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

void LockstepDriver::send(const proto::LockstepStep& step) { impl_->steps.write(0, proto::encode(step)); }

std::optional<proto::LockstepResult> LockstepDriver::next_result(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (impl_->ready.empty()) {
    impl_->results.take([&](const proto::Received& r) {
      std::string why;
      if (auto result = proto::decode_lockstep_result(r.payload, &why))
        impl_->ready.push_back(std::move(*result));
      else
        ++rejected_;
    });
    if (!impl_->ready.empty()) break;
    const auto now = std::chrono::steady_clock::now();
    if (now >= end) return std::nullopt;
    impl_->results.wait(std::min<std::chrono::nanoseconds>(end - now, std::chrono::milliseconds(50)));
  }
  auto r = std::move(impl_->ready.front());
  impl_->ready.pop_front();
  return r;
}

}  // namespace viscera::client
