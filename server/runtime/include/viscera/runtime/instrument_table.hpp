#pragma once  // SPDX-License-Identifier: Apache-2.0
// Who owns which instrument, and each owner's newest command: claims, releases, commands, the
// lease that takes an instrument from a silent owner, and the hand-over of an instrument from
// one client to another (an instructor taking over, and handing back). No DDS and no clock of its
// own: the caller passes the time. Thread-safe: the command thread records commands while the
// physics thread claims, releases and reads the table.
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "viscera/protocol/messages.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace viscera::runtime {

enum class ClaimResult { claimed, already_owner, taken, unknown_instrument };
enum class ReleaseResult { released, not_owner, unknown_instrument };
enum class CommandResult { accepted, stale, not_owner, unknown_instrument };
enum class HandoverResult { handed_over, not_owner, unknown_instrument, already_owner, not_taken_over };

/// What a take-over or a hand-back did: the result and the client the instrument went from.
struct Handover {
  HandoverResult result = HandoverResult::unknown_instrument;
  std::uint32_t from = 0;  ///< the previous owner (0: it was free)
};

/// An instrument and its owner (0: none).
struct Ownership {
  std::uint32_t instrument_id = 0, owner = 0;
  std::uint32_t handed_back_to = 0;  ///< release_silent: the client a silent taker had taken it from, who has it again (0: freed)
  bool operator==(const Ownership&) const = default;
};

/// What a tick steps an instrument with: its owner and newest command, if it has both.
struct TickCommand {
  std::uint32_t instrument_id = 0, owner = 0;
  bool active = false;  ///< owned and commanded since it was claimed
  protocol::Command command;
};

class InstrumentTable {
 public:
  InstrumentTable() = default;
  explicit InstrumentTable(const std::vector<InstrumentSpec>& instruments);
  /// A new scene's instruments; returns the owners of the old ones, who lose them.
  std::vector<Ownership> replace(const std::vector<InstrumentSpec>& instruments);

  /// Claims a free instrument for `client` at `now_ns` (the lease starts).
  ClaimResult claim(std::uint32_t instrument_id, std::uint32_t client, std::int64_t now_ns);
  /// Releases an instrument its owner holds.
  ReleaseResult release(std::uint32_t instrument_id, std::uint32_t client);
  /// `to` takes the instrument over from its owner `from` at once, with no moment in which nobody
  /// owns it; the new owner's commands count from now, so until it sends one the tool stays where
  /// the last command left it.
  HandoverResult hand_over(std::uint32_t instrument_id, std::uint32_t from, std::uint32_t to, std::int64_t now_ns);
  /// `to` takes the instrument from whoever owns it (hand_over, remembering whom from), or claims
  /// it if it is free.
  Handover take_over(std::uint32_t instrument_id, std::uint32_t to, std::int64_t now_ns);
  /// `by`, who took the instrument over, hands it back to the client it took it from (hand_over),
  /// or frees it if it was free when taken over (Handover::from 0).
  Handover hand_back(std::uint32_t instrument_id, std::uint32_t by, std::int64_t now_ns);
  /// A command from `command.client_id`: accepted (the newest) if it owns the instrument and the
  /// sequence is newer; renews the owner's lease either way.
  CommandResult command(const protocol::Command& command, std::int64_t now_ns);
  /// Owners silent (no claim or command) for longer than `lease_ns` at `now_ns` lose their
  /// instruments; returns them. An instrument a silent owner had taken over goes back to the client
  /// it was taken from (whose lease starts again), as a hand-back would; any other is freed.
  std::vector<Ownership> release_silent(std::int64_t now_ns, std::int64_t lease_ns);
  /// The server itself did not run for `stalled_ns` (stopped, swapped out, a paused VM): its
  /// owners could not be heard meanwhile, so that time is not counted as their silence.
  void excuse_stall(std::int64_t stalled_ns);

  /// The owner (0: none), or nullopt for an instrument the scene does not have.
  std::optional<std::uint32_t> owner(std::uint32_t instrument_id) const;
  const std::vector<InstrumentSpec>& specs() const { return specs_; }
  std::vector<protocol::InstrumentInfo> describe() const;
  /// Each instrument's owner and newest command, for the tick about to run.
  std::vector<TickCommand> tick_commands() const;

 private:
  struct Entry {
    std::uint32_t owner = 0;
    bool has_command = false;
    std::int64_t last_heard_ns = 0;  ///< the owner's last claim or command
    protocol::Command last;
    std::uint32_t taken_from = 0;  ///< the owner before a take-over (0: it was free)
    bool taken_over = false;  ///< the owner took it over (and may hand it back)
  };
  HandoverResult hand_over_locked(Entry& e, std::uint32_t from, std::uint32_t to, std::int64_t now_ns);
  std::vector<InstrumentSpec> specs_;
  std::map<std::uint32_t, Entry> entries_;
  mutable std::mutex mutex_;
};

}  // namespace viscera::runtime
