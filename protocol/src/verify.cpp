#include <algorithm>  // SPDX-License-Identifier: Apache-2.0
#include <cctype>
#include <cmath>

#include "viscera/common/plain_name.hpp"
#include "viscera/protocol/messages.hpp"

#include "event_generated.h"
#include "force_feedback_generated.h"
#include "instrument_command_generated.h"
#include "session_generated.h"
#include "telemetry_generated.h"
#include "verified_root.hpp"

namespace viscera::protocol {

namespace fb = viscera::wire;  // the flatc-generated types

namespace {

constexpr double kMaxForceN = 1e4;
constexpr double kMaxFrictionMu = 2.0;  // a scene's friction coefficients are at most 2
constexpr double kMaxEdgeStrain = 10.0;  // the server stops an organ whose edges stretch beyond 2 (unstable); 10: room, not physics

fb::Vec3 to_fb(const Vector3& v) { return fb::Vec3(v[0], v[1], v[2]); }
Vector3 from_fb(const fb::Vec3* v) { return v ? Vector3{v->x(), v->y(), v->z()} : Vector3{0, 0, 0}; }

bool finite(const Vector3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }
bool within(const Vector3& v, double limit) { return std::abs(v[0]) <= limit && std::abs(v[1]) <= limit && std::abs(v[2]) <= limit; }

using detail::kMaxPositionM;
using detail::verified_root;

template <typename B>
std::vector<std::uint8_t> finish(flatbuffers::FlatBufferBuilder& b, flatbuffers::Offset<B> root) {
  b.Finish(root);
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

}  // namespace

std::vector<std::uint8_t> encode(const Command& c) {
  flatbuffers::FlatBufferBuilder b(128);
  const fb::Vec3 tip = to_fb(c.tip_position);
  const fb::Quat q(c.orientation[0], c.orientation[1], c.orientation[2], c.orientation[3]);
  return finish(b, fb::CreateInstrumentCommand(b, c.instrument_id, c.client_id, c.seq, c.client_stamp_ns, &tip, &q, c.jaw_opening, c.buttons));
}

std::vector<std::uint8_t> encode(const Force& f) {
  flatbuffers::FlatBufferBuilder b(256);
  const fb::Vec3 point = to_fb(f.contact_point), normal = to_fb(f.contact_normal), force = to_fb(f.force), torque = to_fb(f.torque);
  const auto& k = f.stiffness;
  const fb::Mat3 K(k[0], k[1], k[2], k[3], k[4], k[5], k[6], k[7], k[8]);
  const auto model = fb::CreateLocalForceModel(b, &point, &normal, &K, f.in_contact);
  return finish(b, fb::CreateForceFeedback(b, f.instrument_id, f.client_id, f.command_seq, f.command_client_stamp_ns, f.server_stamp_ns, &force,
                                           &torque, model, f.step_time_ns, f.penetration_m, f.tick, f.max_edge_strain, f.cutting, f.cut_edge_strain,
                                           f.tip_strain, f.organ_epoch, f.friction_mu));
}

std::vector<std::uint8_t> encode(const SessionRequest& r) {
  flatbuffers::FlatBufferBuilder b(128);
  const auto name = r.scene_name.empty() ? 0 : b.CreateString(r.scene_name);
  flatbuffers::Offset<fb::MaterialChange> material = 0;
  if (!r.material.empty()) {
    // Strings before the table that refers to them (FlatBuffers builds bottom-up).
    const auto file_name = r.material.file_text ? b.CreateString(r.material.file_name) : 0;
    const auto file_text = r.material.file_text ? b.CreateString(*r.material.file_text) : 0;
    fb::MaterialChangeBuilder m(b);
    if (r.material.youngs_modulus_pa) m.add_youngs_modulus_pa(*r.material.youngs_modulus_pa);
    if (r.material.poisson_ratio) m.add_poisson_ratio(*r.material.poisson_ratio);
    if (r.material.density_kg_m3) m.add_density_kg_m3(*r.material.density_kg_m3);
    if (r.material.shear_q) m.add_shear_q(*r.material.shear_q);
    if (r.material.damping_per_s) m.add_damping_per_s(*r.material.damping_per_s);
    if (r.material.file_text) {
      m.add_file_name(file_name);
      m.add_file_text(file_text);
    }
    material = m.Finish();
  }
  return finish(b, fb::CreateSessionRequest(b, r.client_id, static_cast<fb::SessionAction>(r.action), r.instrument_id, r.request_seq, name, material,
                                            r.physics_rate_hz, r.seek_s,
                                            r.scene_seed ? flatbuffers::Optional<std::uint64_t>(*r.scene_seed) : flatbuffers::nullopt));
}

std::vector<std::uint8_t> encode(const Scene& s) {
  flatbuffers::FlatBufferBuilder b(512);
  std::vector<flatbuffers::Offset<fb::InstrumentState>> inst;
  for (const auto& i : s.instruments)
    inst.push_back(fb::CreateInstrumentState(b, i.instrument_id,
                                             i.scalpel   ? fb::InstrumentKind::scalpel
                                             : i.grasper ? fb::InstrumentKind::grasper
                                                         : fb::InstrumentKind::probe,
                                             i.tip_radius_m, i.owner_client_id, i.blade_length_m));
  const auto name = b.CreateString(s.name);
  const auto list = b.CreateVector(inst);
  const fb::Vec3 lo = to_fb(s.bounds_min), hi = to_fb(s.bounds_max);
  const auto& m = s.material;
  const auto material = fb::CreateMaterialState(b, b.CreateString(m.name), m.youngs_modulus_pa, m.poisson_ratio, m.density_kg_m3, m.shear_q,
                                                m.damping_per_s, m.added_mass_fraction);
  const auto scenes = b.CreateVectorOfStrings(s.available_scenes);
  const auto preparing = b.CreateString(s.preparing);
  std::vector<flatbuffers::Offset<fb::RequestOutcome>> outcomes;
  for (const auto& o : s.recent_requests)
    outcomes.push_back(
        fb::CreateRequestOutcome(b, o.client_id, o.request_seq, static_cast<fb::SessionAction>(o.action), o.accepted, b.CreateString(o.message)));
  const auto recent = b.CreateVector(outcomes);
  const auto unreadable = b.CreateVectorOfStrings(s.unreadable_scenes);
  std::vector<flatbuffers::Offset<fb::RegionState>> region_list;
  for (const auto& r : s.regions) {
    const fb::Vec3 c = to_fb(r.center), bmin = to_fb(r.box_min), bmax = to_fb(r.box_max);
    region_list.push_back(fb::CreateRegionState(b, b.CreateString(r.name), static_cast<fb::RegionShape>(r.shape), &c, r.radius_m, &bmin, &bmax,
                                                r.depth_m, r.elements, r.volume_m3, b.CreateString(r.material_name), r.youngs_modulus_pa));
  }
  const auto regions = b.CreateVector(region_list);
  return finish(b, fb::CreateSceneState(b, name, s.physics_rate_hz, s.paused, list, &lo, &hi, s.generation, material, scenes, preparing, recent,
                                        unreadable, regions));
}

std::vector<std::uint8_t> encode(const TelemetryReport& t) {
  flatbuffers::FlatBufferBuilder b(128);
  return finish(b, fb::CreateTelemetry(b, t.server_stamp_ns, t.steps, t.physics_rate_hz, t.step_p50_us, t.step_p99_us, t.step_max_us, t.jitter_p99_us,
                                       t.late_ticks, t.rejected_messages, t.missed_slots, t.rejected_malformed, t.rejected_not_owner,
                                       t.rejected_unknown_instrument, t.rejected_other_participant));
}

std::vector<std::uint8_t> encode(const Event& e) {
  flatbuffers::FlatBufferBuilder b(128 + e.text.size());
  const auto text = b.CreateString(e.text);
  const auto scene = e.scene.empty() ? flatbuffers::Offset<flatbuffers::String>() : b.CreateString(e.scene);
  b.Finish(fb::CreateEvent(b, e.source_client_id, static_cast<fb::EventKind>(e.kind), e.instrument_id, e.client_id, e.sim_time_s, e.stamp_ns, text,
                           e.tick, e.request_seq, static_cast<fb::EventReason>(e.reason), scene),
           fb::EventIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

std::optional<Command> decode_command(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::InstrumentCommand>(bytes, why);
  if (!m) return std::nullopt;
  Command c;
  c.instrument_id = m->instrument_id();
  c.client_id = m->client_id();
  c.seq = m->seq();
  c.client_stamp_ns = m->client_stamp_ns();
  if (!m->tip_position()) {
    *why = "tip_position missing";
    return std::nullopt;
  }
  c.tip_position = from_fb(m->tip_position());
  if (m->orientation()) c.orientation = {m->orientation()->w(), m->orientation()->x(), m->orientation()->y(), m->orientation()->z()};
  c.jaw_opening = m->jaw_opening();
  c.buttons = m->buttons();
  if (!finite(c.tip_position) || !within(c.tip_position, kMaxPositionM)) {
    *why = "tip_position is not finite or beyond 10 m";
    return std::nullopt;
  }
  double qn = 0;
  for (double q : c.orientation) qn += q * q;
  if (!std::isfinite(qn) || std::abs(qn - 1.0) > 1e-3) {
    *why = "orientation is not a unit quaternion";
    return std::nullopt;
  }
  if (!std::isfinite(c.jaw_opening) || c.jaw_opening < 0 || c.jaw_opening > M_PI) {
    *why = "jaw_opening outside [0, pi] rad";
    return std::nullopt;
  }
  if (c.client_id == 0) {
    *why = "client_id 0 is reserved";
    return std::nullopt;
  }
  return c;
}

std::optional<Force> decode_force(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::ForceFeedback>(bytes, why);
  if (!m) return std::nullopt;
  Force f;
  f.instrument_id = m->instrument_id();
  f.client_id = m->client_id();
  f.command_seq = m->command_seq();
  f.command_client_stamp_ns = m->command_client_stamp_ns();
  f.server_stamp_ns = m->server_stamp_ns();
  f.step_time_ns = m->step_time_ns();
  f.force = from_fb(m->force());
  f.torque = from_fb(m->torque());
  f.penetration_m = m->penetration_m();
  f.tick = m->tick();
  f.max_edge_strain = m->max_edge_strain();
  f.cutting = m->cutting();
  f.cut_edge_strain = m->cut_edge_strain();
  f.tip_strain = m->tip_strain();
  f.organ_epoch = m->organ_epoch();
  f.friction_mu = m->friction_mu();
  if (const auto* lm = m->local_model()) {
    f.in_contact = lm->in_contact();
    f.contact_point = from_fb(lm->point());
    f.contact_normal = from_fb(lm->normal());
    if (const auto* k = lm->stiffness()) f.stiffness = {k->m00(), k->m01(), k->m02(), k->m10(), k->m11(), k->m12(), k->m20(), k->m21(), k->m22()};
  }
  if (!finite(f.force) || !within(f.force, kMaxForceN) || !finite(f.torque) || !finite(f.contact_point) || !std::isfinite(f.penetration_m) ||
      std::abs(f.penetration_m) > kMaxPositionM || !(f.max_edge_strain >= 0 && f.max_edge_strain <= kMaxEdgeStrain) ||
      !(f.cut_edge_strain >= 0 && f.cut_edge_strain <= kMaxEdgeStrain) || !(f.tip_strain >= 0 && f.tip_strain <= kMaxEdgeStrain) ||
      !(f.friction_mu >= 0 && f.friction_mu <= kMaxFrictionMu)) {
    *why = "force, torque, contact point, penetration, edge strain or friction not finite or out of range";
    return std::nullopt;
  }
  for (double k : f.stiffness)
    if (!std::isfinite(k)) {
      *why = "stiffness not finite";
      return std::nullopt;
    }
  return f;
}

std::optional<SessionRequest> decode_session_request(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::SessionRequest>(bytes, why);
  if (!m) return std::nullopt;
  const auto a = static_cast<int>(m->action());
  if (a < 0 || a > static_cast<int>(Action::hand_back)) {
    *why = "unknown action " + std::to_string(a);
    return std::nullopt;
  }
  if (m->client_id() == 0) {
    *why = "client_id 0 is reserved";
    return std::nullopt;
  }
  SessionRequest r{m->client_id(), static_cast<Action>(a), m->instrument_id(), m->request_seq(), {}, {}, m->physics_rate_hz(), m->seek_s(), {}};
  if (r.action == Action::load_scene && m->scene_seed().has_value()) r.scene_seed = *m->scene_seed();
  if (r.action == Action::load_scene) {
    r.scene_name = m->scene_name() ? m->scene_name()->str() : "";
    if (!common::is_plain_name(r.scene_name)) {
      *why = "scene_name '" + r.scene_name.substr(0, 64) + "' is not a plain scene name ([A-Za-z0-9._-], 1-64 characters, no leading '.')";
      return std::nullopt;
    }
  }
  if (r.action == Action::set_material) {
    const auto* c = m->material();
    if (!c) {
      *why = "set_material without material";
      return std::nullopt;
    }
    const auto take = [&](flatbuffers::Optional<double> v, const char* field, double lo, double hi, bool open_hi, std::optional<double>& out) {
      if (!v.has_value()) return true;
      const double x = *v;
      if (!std::isfinite(x) || x < lo || (open_hi ? x >= hi : x > hi)) {
        *why = std::string("material.") + field + " = " + std::to_string(x) + " is out of range";
        return false;
      }
      out = x;
      return true;
    };
    if (!take(c->youngs_modulus_pa(), "youngs_modulus_pa", 1.0, 1e9, false, r.material.youngs_modulus_pa) ||
        !take(c->poisson_ratio(), "poisson_ratio", 0.0, 0.5, true, r.material.poisson_ratio) ||
        !take(c->density_kg_m3(), "density_kg_m3", 1.0, 1e5, false, r.material.density_kg_m3) ||
        !take(c->shear_q(), "shear_q", 0.5, 1e4, false, r.material.shear_q) ||
        !take(c->damping_per_s(), "damping_per_s", 0.0, 1e4, false, r.material.damping_per_s))
      return std::nullopt;
    if (c->file_text()) {
      if (c->file_text()->size() > kMaxMaterialFileBytes) {
        *why = "material.file_text of " + std::to_string(c->file_text()->size()) + " bytes is longer than " + std::to_string(kMaxMaterialFileBytes);
        return std::nullopt;
      }
      r.material.file_name = c->file_name() ? c->file_name()->str() : "";
      if (!common::is_plain_name(r.material.file_name)) {
        *why = "material.file_name '" + r.material.file_name.substr(0, 64) +
               "' is not a plain file name ([A-Za-z0-9._-], 1-64 characters, no leading '.')";
        return std::nullopt;
      }
      r.material.file_text = c->file_text()->str();
    }
    if (r.material.empty()) {
      *why = "set_material with no parameter";
      return std::nullopt;
    }
  }
  if (r.action == Action::set_physics_rate && !(r.physics_rate_hz >= 10.0 && r.physics_rate_hz <= 10000.0)) {
    *why = "physics_rate_hz = " + std::to_string(r.physics_rate_hz) + " is outside [10, 10000] Hz";
    return std::nullopt;
  }
  if (r.action == Action::seek && !(std::isfinite(r.seek_s) && r.seek_s >= 0.0)) {
    *why = "seek_s = " + std::to_string(r.seek_s) + " is not a time from the start [s]";
    return std::nullopt;
  }
  return r;
}

std::optional<Scene> decode_scene(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::SceneState>(bytes, why);
  if (!m) return std::nullopt;
  Scene s;
  s.name = m->scene_name() ? m->scene_name()->str() : "";
  s.physics_rate_hz = m->physics_rate_hz();
  s.paused = m->paused();
  if (m->instruments())
    for (const auto* i : *m->instruments())
      s.instruments.push_back({i->instrument_id(), i->kind() == fb::InstrumentKind::grasper, i->tip_radius_m(), i->owner_client_id(),
                               i->kind() == fb::InstrumentKind::scalpel, i->blade_length_m()});
  s.bounds_min = from_fb(m->organ_bounds_min());
  s.bounds_max = from_fb(m->organ_bounds_max());
  s.generation = m->generation();
  if (const auto* mat = m->material()) {
    s.material = {mat->name() ? mat->name()->str() : "",
                  mat->youngs_modulus_pa(),
                  mat->poisson_ratio(),
                  mat->density_kg_m3(),
                  mat->shear_q(),
                  mat->damping_per_s(),
                  mat->added_mass_fraction()};
    const auto& x = s.material;
    if (!std::isfinite(x.youngs_modulus_pa + x.poisson_ratio + x.density_kg_m3 + x.shear_q + x.damping_per_s + x.added_mass_fraction)) {
      *why = "material numbers not finite";
      return std::nullopt;
    }
  }
  if (m->available_scenes())
    for (const auto* n : *m->available_scenes()) s.available_scenes.push_back(n->str());
  s.preparing = m->preparing() ? m->preparing()->str() : "";
  if (m->unreadable_scenes())
    for (const auto* n : *m->unreadable_scenes()) s.unreadable_scenes.push_back(n->str());
  if (m->regions())
    for (const auto* r : *m->regions()) {
      RegionInfo i{r->name() ? r->name()->str() : "",
                   static_cast<RegionShape>(r->shape()),
                   from_fb(r->center()),
                   r->radius_m(),
                   from_fb(r->box_min()),
                   from_fb(r->box_max()),
                   r->depth_m(),
                   r->elements(),
                   r->volume_m3(),
                   r->material_name() ? r->material_name()->str() : "",
                   r->youngs_modulus_pa()};
      if (r->shape() > fb::RegionShape::MAX) {
        *why = "region '" + i.name.substr(0, 64) + "': unknown shape " + std::to_string(static_cast<int>(r->shape()));
        return std::nullopt;
      }
      if (!finite(i.center) || !finite(i.box_min) || !finite(i.box_max) ||
          !std::isfinite(i.radius_m + i.depth_m + i.volume_m3 + i.youngs_modulus_pa) || i.radius_m < 0) {
        *why = "region '" + i.name.substr(0, 64) + "': numbers not finite";
        return std::nullopt;
      }
      s.regions.push_back(std::move(i));
    }
  if (m->recent_requests())
    for (const auto* o : *m->recent_requests())
      s.recent_requests.push_back(
          {o->client_id(), o->request_seq(), static_cast<Action>(o->action()), o->accepted(), o->message() ? o->message()->str() : ""});
  if (!finite(s.bounds_min) || !finite(s.bounds_max) || !std::isfinite(s.physics_rate_hz)) {
    *why = "scene numbers not finite";
    return std::nullopt;
  }
  return s;
}

std::optional<TelemetryReport> decode_telemetry(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::Telemetry>(bytes, why);
  if (!m) return std::nullopt;
  TelemetryReport t{m->server_stamp_ns(),
                    m->steps(),
                    m->overruns(),
                    m->rejected_messages(),
                    m->physics_rate_hz(),
                    m->step_time_p50_us(),
                    m->step_time_p99_us(),
                    m->step_time_max_us(),
                    m->tick_jitter_p99_us(),
                    m->missed_slots(),
                    m->rejected_malformed(),
                    m->rejected_not_owner(),
                    m->rejected_unknown_instrument(),
                    m->rejected_other_participant()};
  const std::pair<const char*, double> figures[] = {{"physics_rate_hz", t.physics_rate_hz},
                                                    {"step_time_p50_us", t.step_p50_us},
                                                    {"step_time_p99_us", t.step_p99_us},
                                                    {"step_time_max_us", t.step_max_us},
                                                    {"tick_jitter_p99_us", t.jitter_p99_us}};
  for (const auto& [name, v] : figures)
    if (!std::isfinite(v) || v < 0) {
      *why = std::string(name) + " is " + std::to_string(v) + " (a rate or a time: finite, >= 0)";
      return std::nullopt;
    }
  return t;
}

std::optional<Event> decode_event(std::span<const std::uint8_t> bytes, std::string* why) {
  const auto* m = verified_root<fb::Event>(bytes, why, fb::EventIdentifier());
  if (!m) return std::nullopt;
  // Kinds this build does not know (added by a newer server) pass through: event_name() says
  // "unknown". Negative kinds are never defined.
  const auto k = static_cast<int>(m->kind());
  if (k < 0) {
    *why = "negative event kind " + std::to_string(k);
    return std::nullopt;
  }
  if (m->text() && m->text()->size() > 1024) {
    *why = "text of " + std::to_string(m->text()->size()) + " bytes (at most 1024)";
    return std::nullopt;
  }
  if (!std::isfinite(m->sim_time_s()) || m->sim_time_s() < 0) {
    *why = "sim_time_s not finite or negative";
    return std::nullopt;
  }
  // Reasons this build does not know pass through as kinds do; negative ones are never defined.
  if (static_cast<int>(m->reason()) < 0) {
    *why = "negative event reason " + std::to_string(static_cast<int>(m->reason()));
    return std::nullopt;
  }
  if (m->scene() && m->scene()->size() > 64) {
    *why = "scene name of " + std::to_string(m->scene()->size()) + " bytes (at most 64)";
    return std::nullopt;
  }
  return Event{m->source_client_id(),
               static_cast<EventKind>(k),
               m->instrument_id(),
               m->client_id(),
               m->sim_time_s(),
               m->stamp_ns(),
               m->text() ? m->text()->str() : "",
               m->tick(),
               m->request_seq(),
               static_cast<EventReason>(m->reason()),
               m->scene() ? m->scene()->str() : ""};
}

}  // namespace viscera::protocol
