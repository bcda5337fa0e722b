#pragma once
// Which DDS participant speaks for each client id on the instruments. Every message names its
// client id, and the server used to believe it: a second process started with another's id took
// over that client's instrument. Now the first participant to command, claim, release, take over
// or hand back under an id holds it while it keeps talking; another participant using the same id
// there is refused until the holder has been silent for the lease (the instruments' lease: a
// crashed client's id comes free when its instruments do). Under DDS Security each participant is
// an authenticated identity, so no identity can act under an id another one holds (docs/DEPLOY.md).
#include <cstdint>
#include <mutex>
#include <unordered_map>

namespace viscera::runtime {

class ClientBinding {
 public:
  explicit ClientBinding(std::int64_t lease_ns) : lease_ns_(lease_ns) {}
  /// Whether `participant` (protocol::Received::participant) may act as `client_id` at `now_ns`:
  /// yes if the id is free, is already this participant's, or its holder has been silent longer
  /// than the lease (the id then passes to this participant). Thread-safe.
  bool admit(std::uint32_t client_id, std::uint64_t participant, std::int64_t now_ns);
  /// Ids held now (for tests and statistics).
  std::size_t held() const;

 private:
  struct Holder {
    std::uint64_t participant;
    std::int64_t last_ns;
  };
  std::int64_t lease_ns_;
  std::unordered_map<std::uint32_t, Holder> holders_;
  mutable std::mutex mutex_;
};

}  // namespace viscera::runtime
