// The names of the protocol's enumerations, as logs, events and the console show them.  // SPDX-License-Identifier: Apache-2.0
#include "viscera/protocol/messages.hpp"

namespace viscera::protocol {

const char* action_name(Action a) {
  switch (a) {
    case Action::claim_instrument: return "claim_instrument";
    case Action::release_instrument: return "release_instrument";
    case Action::pause: return "pause";
    case Action::resume: return "resume";
    case Action::reset: return "reset";
    case Action::load_scene: return "load_scene";
    case Action::set_material: return "set_material";
    case Action::set_physics_rate: return "set_physics_rate";
    case Action::seek: return "seek";
    case Action::take_over: return "take_over";
    case Action::hand_back: return "hand_back";
  }
  return "unknown";
}

const char* event_reason_name(EventReason r) {
  switch (r) {
    case EventReason::unspecified: return "unspecified";
    case EventReason::by_owner: return "by_owner";
    case EventReason::owner_silent: return "owner_silent";
    case EventReason::scene_replaced: return "scene_replaced";
    case EventReason::handed_back: return "handed_back";
  }
  return "unknown";
}

const char* event_name(EventKind k) {
  switch (k) {
    case EventKind::annotation: return "annotation";
    case EventKind::instrument_claimed: return "instrument_claimed";
    case EventKind::instrument_released: return "instrument_released";
    case EventKind::paused: return "paused";
    case EventKind::resumed: return "resumed";
    case EventKind::organ_reset: return "organ_reset";
    case EventKind::physics_reset: return "physics_reset";
    case EventKind::contact_started: return "contact_started";
    case EventKind::contact_ended: return "contact_ended";
    case EventKind::grasped: return "grasped";
    case EventKind::let_go: return "let_go";
    case EventKind::scene_loaded: return "scene_loaded";
    case EventKind::material_changed: return "material_changed";
    case EventKind::physics_rate_changed: return "physics_rate_changed";
    case EventKind::request_refused: return "request_refused";
    case EventKind::cut_started: return "cut_started";
    case EventKind::cut_ended: return "cut_ended";
  }
  return "unknown";
}

}  // namespace viscera::protocol
