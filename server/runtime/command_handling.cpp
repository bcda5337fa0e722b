// The commands of the simulation server: answered at once on the command thread, or in lockstep  // SPDX-License-Identifier: Apache-2.0
// from a recording's steps.
#include "simulation_server_impl.hpp"

namespace viscera::runtime {

using namespace viscera::tissue;

/// A command's payload decoded, or counted as malformed.
std::optional<proto::Command> SimulationServer::Impl::decode_counted(std::span<const std::uint8_t> payload) {
  std::string why;
  auto c = proto::decode_command(payload, &why);
  if (!c) ++counted.malformed;
  return c;
}

/// A command offered to its instrument, a refusal counted; whether it became the newest.
bool SimulationServer::Impl::offer_counted(const proto::Command& c, std::int64_t now_ns) {
  switch (instruments.command(c, now_ns)) {
    case CommandResult::accepted: return true;
    case CommandResult::stale: return false;
    case CommandResult::not_owner: ++counted.not_owner; return false;
    case CommandResult::unknown_instrument: ++counted.unknown_instrument; return false;
  }
  return false;
}

/// Each valid command from an instrument's owner becomes the instrument's newest command and is
/// answered at once with the reaction at the commanded pose on the newest snapshot (contact
/// query, no step). The next tick steps the tissue with it.
void SimulationServer::Impl::answer_new_commands() {
  struct Update {
    std::uint32_t id, owner;
    proto::Command command;
  };
  std::vector<Update> updated;
  std::lock_guard world(organ_mutex);  // the organ and the responder's queries stay while we answer
  endpoints.take_commands([&](const proto::Received& r) {
    const auto c = decode_counted(r.payload);
    if (!c) return;
    const std::int64_t now = proto::now_ns();
    if (!clients.admit(c->client_id, {r.participant, r.identity}, now)) {
      ++counted.other_participant;
      return;
    }
    if (offer_counted(*c, now)) updated.push_back({c->instrument_id, c->client_id, *c});
  });
  for (const auto& u : updated) {
    std::shared_ptr<const Snapshot> used;
    const ContactResult r = responder.answer(u.id, u.command, &used);
    publish_force(u.id, u.owner, u.command, r, 0, used->tick, used->max_edge_strain, used->organ_epoch);
  }
}

/// Lockstep: the step's answers, on the state the previous tick left (as the command thread
/// answers them live); they do not become the instruments' commands. Ownership is not checked
/// again: the live server answered them, so their client owned the instrument then, and a claim
/// or release in the same step may have come before or after them live (the order of the two
/// within one tick's interval is not recorded).
void SimulationServer::Impl::answer_in_lockstep(const std::vector<std::vector<std::uint8_t>>& answers) {
  for (const auto& payload : answers) {
    const auto c = decode_counted(payload);
    if (!c) continue;
    if (!instruments.owner(c->instrument_id)) {
      ++counted.unknown_instrument;
      continue;
    }
    std::shared_ptr<const Snapshot> used;
    const ContactResult r = responder.answer(c->instrument_id, *c, &used);
    publish_force(c->instrument_id, c->client_id, *c, r, 0, used->tick, used->max_edge_strain, used->organ_epoch);
  }
}

/// Lockstep: the step's commands become their instruments' newest (the live command thread's
/// other half).
void SimulationServer::Impl::command_in_lockstep(const std::vector<std::vector<std::uint8_t>>& commands) {
  for (const auto& payload : commands)
    if (const auto c = decode_counted(payload)) offer_counted(*c, 0);
}

}  // namespace viscera::runtime
