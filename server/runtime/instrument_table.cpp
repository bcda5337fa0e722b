#include "viscera/runtime/instrument_table.hpp"  // SPDX-License-Identifier: Apache-2.0

namespace viscera::runtime {

InstrumentTable::InstrumentTable(const std::vector<InstrumentSpec>& instruments) { replace(instruments); }

std::vector<Ownership> InstrumentTable::replace(const std::vector<InstrumentSpec>& instruments) {
  std::lock_guard lock(mutex_);
  std::vector<Ownership> lost;
  for (const auto& [id, e] : entries_)
    if (e.owner != 0) lost.push_back({id, e.owner});
  specs_ = instruments;
  entries_.clear();
  for (const auto& s : specs_) entries_[s.id] = {};
  return lost;
}

ClaimResult InstrumentTable::claim(std::uint32_t instrument_id, std::uint32_t client, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(instrument_id);
  if (it == entries_.end()) return ClaimResult::unknown_instrument;
  Entry& e = it->second;
  if (e.owner == client) {
    e.last_heard_ns = now_ns;
    return ClaimResult::already_owner;
  }
  if (e.owner != 0) return ClaimResult::taken;  // no fault: its owner may let it go
  e = {client, false, now_ns, {}};
  return ClaimResult::claimed;
}

ReleaseResult InstrumentTable::release(std::uint32_t instrument_id, std::uint32_t client) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(instrument_id);
  if (it == entries_.end()) return ReleaseResult::unknown_instrument;
  if (it->second.owner != client) return ReleaseResult::not_owner;
  it->second = {};
  return ReleaseResult::released;
}

HandoverResult InstrumentTable::hand_over(std::uint32_t instrument_id, std::uint32_t from, std::uint32_t to, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(instrument_id);
  if (it == entries_.end()) return HandoverResult::unknown_instrument;
  return hand_over_locked(it->second, from, to, now_ns);
}

Handover InstrumentTable::take_over(std::uint32_t instrument_id, std::uint32_t to, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(instrument_id);
  if (it == entries_.end()) return {HandoverResult::unknown_instrument, 0};
  Entry& e = it->second;
  const std::uint32_t from = e.owner;
  if (from == to) return {HandoverResult::already_owner, from};
  if (from == 0) {
    e = {to, false, now_ns, {}, 0, true};
    return {HandoverResult::handed_over, 0};
  }
  hand_over_locked(e, from, to, now_ns);
  e.taken_from = from;
  e.taken_over = true;
  return {HandoverResult::handed_over, from};
}

Handover InstrumentTable::hand_back(std::uint32_t instrument_id, std::uint32_t by, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(instrument_id);
  if (it == entries_.end()) return {HandoverResult::unknown_instrument, 0};
  Entry& e = it->second;
  if (e.owner != by) return {HandoverResult::not_owner, 0};
  if (!e.taken_over) return {HandoverResult::not_taken_over, 0};
  const std::uint32_t to = e.taken_from;
  if (to == 0) {  // it was free: free again, for whoever claims it next
    e = {};
    return {HandoverResult::handed_over, 0};
  }
  hand_over_locked(e, by, to, now_ns);
  e.taken_from = 0;
  e.taken_over = false;
  return {HandoverResult::handed_over, to};
}

HandoverResult InstrumentTable::hand_over_locked(Entry& e, std::uint32_t from, std::uint32_t to, std::int64_t now_ns) {
  if (e.owner != from || from == 0) return HandoverResult::not_owner;
  e.owner = to;
  e.last_heard_ns = now_ns;
  // The previous owner's newest command stays the tool's pose until the new owner sends one; its
  // sequence belongs to another client, so the new owner's first command is taken whatever its seq.
  e.last.client_id = to;
  e.last.seq = 0;
  return HandoverResult::handed_over;
}

CommandResult InstrumentTable::command(const protocol::Command& c, std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(c.instrument_id);
  if (it == entries_.end()) return CommandResult::unknown_instrument;
  Entry& e = it->second;
  if (e.owner != c.client_id) return CommandResult::not_owner;
  e.last_heard_ns = now_ns;
  if (e.has_command && c.seq <= e.last.seq) return CommandResult::stale;
  e.last = c;
  e.has_command = true;
  return CommandResult::accepted;
}

std::vector<Ownership> InstrumentTable::release_silent(std::int64_t now_ns, std::int64_t lease_ns) {
  std::lock_guard lock(mutex_);
  std::vector<Ownership> released;
  for (auto& [id, e] : entries_)
    if (e.owner != 0 && now_ns - e.last_heard_ns > lease_ns) {
      const std::uint32_t back = e.taken_over ? e.taken_from : 0;
      released.push_back({id, e.owner, back});
      if (back != 0) {  // a console that took it over died or went silent: the trainee has it again
        hand_over_locked(e, e.owner, back, now_ns);
        e.taken_from = 0;
        e.taken_over = false;
      } else {
        e = {};
      }
    }
  return released;
}

void InstrumentTable::excuse_stall(std::int64_t stalled_ns) {
  std::lock_guard lock(mutex_);
  for (auto& [id, e] : entries_)
    if (e.owner != 0) e.last_heard_ns += stalled_ns;
}

std::optional<std::uint32_t> InstrumentTable::owner(std::uint32_t instrument_id) const {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(instrument_id);
  if (it == entries_.end()) return std::nullopt;
  return it->second.owner;
}

std::vector<protocol::InstrumentInfo> InstrumentTable::describe() const {
  std::lock_guard lock(mutex_);
  std::vector<protocol::InstrumentInfo> out;
  for (const auto& s : specs_)
    out.push_back({s.id, s.kind == InstrumentKind::grasper, s.tip_radius_m, entries_.at(s.id).owner, s.kind == InstrumentKind::scalpel,
                   s.kind == InstrumentKind::scalpel ? s.blade_length_m : 0.0});
  return out;
}

std::vector<TickCommand> InstrumentTable::tick_commands() const {
  std::lock_guard lock(mutex_);
  std::vector<TickCommand> out;
  for (const auto& s : specs_) {
    const Entry& e = entries_.at(s.id);
    out.push_back({s.id, e.owner, e.owner != 0 && e.has_command, e.last});
  }
  return out;
}

}  // namespace viscera::runtime
