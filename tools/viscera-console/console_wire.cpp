#include "viscera/console/console_wire.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cstring>

namespace viscera::console {

namespace {

template <class T>
void put(std::string& out, std::size_t at, T v) {
  std::memcpy(out.data() + at, &v, sizeof v);  // little-endian hosts only (x86-64, aarch64)
}

}  // namespace

std::string encode_topology(const protocol::SurfaceTopology& t) {
  const std::size_t nv = t.rest_positions.size(), ni = t.triangles.size();
  std::string out(kTopologyHeaderBytes + 4 * (nv + ni), '\0');
  out[0] = static_cast<char>(BinaryKind::topology);
  put<std::uint32_t>(out, 4, t.mesh_id);
  put<std::uint32_t>(out, 8, t.vertex_count);
  put<std::uint32_t>(out, 12, static_cast<std::uint32_t>(ni / 3));
  put<std::uint32_t>(out, 16, t.topology_generation);
  std::memcpy(out.data() + kTopologyHeaderBytes, t.rest_positions.data(), 4 * nv);
  std::memcpy(out.data() + kTopologyHeaderBytes + 4 * nv, t.triangles.data(), 4 * ni);
  return out;
}

std::string encode_frame(const protocol::MeshFrame& m, double server_wall_ms) {
  std::string out(kFrameHeaderBytes + 4 * m.positions.size(), '\0');
  out[0] = static_cast<char>(BinaryKind::frame);
  put<std::uint32_t>(out, 4, m.mesh_id);
  put<std::uint32_t>(out, 8, static_cast<std::uint32_t>(m.positions.size() / 3));
  put<std::uint32_t>(out, 12, m.topology_generation);
  put<double>(out, 16, static_cast<double>(m.frame));
  put<double>(out, 24, m.sim_time_s);
  put<double>(out, 32, server_wall_ms);
  std::memcpy(out.data() + kFrameHeaderBytes, m.positions.data(), 4 * m.positions.size());
  return out;
}

nlohmann::json to_json(const protocol::Scene& s) {
  nlohmann::json instruments = nlohmann::json::array();
  for (const auto& i : s.instruments)
    instruments.push_back({{"id", i.instrument_id},
                           {"grasper", i.grasper},
                           {"kind", i.scalpel   ? "scalpel"
                                    : i.grasper ? "grasper"
                                                : "probe"},
                           {"tip_radius_m", i.tip_radius_m},
                           {"blade_length_m", i.blade_length_m},
                           {"owner", i.owner_client_id}});
  nlohmann::json outcomes = nlohmann::json::array();
  for (const auto& o : s.recent_requests)
    outcomes.push_back({{"client_id", o.client_id}, {"action", protocol::action_name(o.action)}, {"accepted", o.accepted}, {"message", o.message}});
  const auto& m = s.material;
  return {{"type", "scene"},
          {"name", s.name},
          {"generation", s.generation},
          {"paused", s.paused},
          {"physics_rate_hz", s.physics_rate_hz},
          {"bounds_min", s.bounds_min},
          {"bounds_max", s.bounds_max},
          {"instruments", instruments},
          {"material",
           {{"name", m.name},
            {"youngs_modulus_pa", m.youngs_modulus_pa},
            {"poisson_ratio", m.poisson_ratio},
            {"density_kg_m3", m.density_kg_m3},
            {"shear_q", m.shear_q},
            {"damping_per_s", m.damping_per_s}}},
          {"available_scenes", s.available_scenes},
          {"preparing", s.preparing},
          {"recent_requests", outcomes}};
}

nlohmann::json to_json(const protocol::TelemetryReport& t) {
  return {{"type", "telemetry"},
          {"physics_rate_hz", t.physics_rate_hz},
          {"step_p50_us", t.step_p50_us},
          {"step_p99_us", t.step_p99_us},
          {"step_max_us", t.step_max_us},
          {"jitter_p99_us", t.jitter_p99_us},
          {"steps", t.steps},
          {"late_ticks", t.late_ticks},
          {"missed_slots", t.missed_slots},
          {"rejected_messages", t.rejected_messages}};
}

nlohmann::json to_json(const protocol::Event& e) {
  return {{"type", "event"},
          {"kind", protocol::event_name(e.kind)},
          {"source_client_id", e.source_client_id},
          {"instrument_id", e.instrument_id},
          {"client_id", e.client_id},
          {"sim_time_s", e.sim_time_s},
          {"text", e.text}};
}

nlohmann::json forces_json(const std::vector<ForceSummary>& f, const std::vector<std::pair<std::uint32_t, protocol::Vector3>>& tips) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : f) {
    nlohmann::json i = {{"id", s.instrument_id},
                        {"t_s", s.t_s},
                        {"peak_n", s.peak_n},
                        {"force", s.force},
                        {"contact", s.in_contact},
                        {"contact_point", s.contact_point},
                        {"max_edge_strain", s.max_edge_strain},
                        {"tip_strain", s.tip_strain}};
    for (const auto& [id, tip] : tips)
      if (id == s.instrument_id) i["tip"] = tip;
    list.push_back(std::move(i));
  }
  return {{"type", "forces"}, {"instruments", list}};
}

}  // namespace viscera::console
