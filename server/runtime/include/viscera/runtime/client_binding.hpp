#pragma once  // SPDX-License-Identifier: Apache-2.0
// Which sender speaks for each client id on the instruments. Every message names its client id,
// and the server used to believe it: a second process started with another's id took over that
// client's instrument. Now the first DDS participant to command, claim, release, take over or hand
// back under an id holds it while it keeps talking; another participant using the same id there is
// refused until the holder has been silent for the lease (the instruments' lease: a crashed
// client's id comes free when its instruments do). Under DDS Security (bound by identity) an id
// also stays with the certificate that first used it, for the server's life: a participant of
// another certificate is refused however long the holder has been silent, while a restarted client
// with the same certificate takes its id back after the lease (docs/DEPLOY.md).
#include <cstdint>
#include <mutex>
#include <unordered_map>

namespace viscera::runtime {

/// Who sent a message (protocol::Received::participant and ::identity).
struct Sender {
  std::uint64_t participant = 0;
  std::uint64_t identity = 0;  ///< the certificate's, under DDS Security
};

class ClientBinding {
 public:
  /// `by_identity`: ids stay with the certificate that first used them (only where DDS Security
  /// authenticates the identities; without it an identity is a process).
  ClientBinding(std::int64_t lease_ns, bool by_identity) : lease_ns_(lease_ns), by_identity_(by_identity) {}
  /// Whether `from` may act as `client_id` at `now_ns`: yes if the id is free or already this
  /// participant's; or if its holder has been silent longer than the lease (the id then passes to
  /// this participant) and, bound by identity, this participant has the holder's identity.
  /// Thread-safe.
  bool admit(std::uint32_t client_id, const Sender& from, std::int64_t now_ns);
  bool by_identity() const { return by_identity_; }
  /// Ids held now (for tests and statistics).
  std::size_t held() const;

 private:
  struct Holder {
    Sender sender;
    std::int64_t last_ns;
  };
  std::int64_t lease_ns_;
  bool by_identity_;
  std::unordered_map<std::uint32_t, Holder> holders_;
  mutable std::mutex mutex_;
};

}  // namespace viscera::runtime
