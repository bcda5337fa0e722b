#include "simulation_server.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <thread>

#include "common/input_error.hpp"
#include "integrator/explicit_integrator.hpp"
#include "material/material_file.hpp"
#include "mesh/boundary_surface.hpp"
#include "mesh/mesh_reader.hpp"
#include "mesh/refinement.hpp"
#include "contact_compliance.hpp"
#include "mesh_publisher.hpp"
#include "model/model_factory.hpp"
#include "probe_contact.hpp"
#include "viscera/protocol/dds.hpp"
#include "viscera/protocol/messages.hpp"
#include "viscoelastic/viscoelastic_material.hpp"

namespace viscera::runtime {

namespace proto = viscera::protocol;
using namespace viscera::tissue;

namespace {
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}
}  // namespace

struct SimulationServer::Impl {
  SceneSpec scene;
  std::shared_ptr<TetMesh> mesh;
  std::unique_ptr<ForceModel> model;
  std::unique_ptr<ExplicitIntegrator> integrator;
  std::unique_ptr<ContactCompliance> compliance;  // worker thread; uses *model
  State state;
  double sim_time_s = 0;
  Box bounds;

  struct Instrument {
    InstrumentSpec spec;
    std::unique_ptr<ProbeContact> contact;
    std::uint32_t owner = 0;
    bool has_command = false;
    std::int64_t last_heard_ns = 0;  // owner's last command or claim
    // Grasper: nodes held by the closed jaws, with their offsets from the tip when grasped.
    std::vector<std::pair<std::int32_t, Vec3>> grasped;
    proto::Command last;
    // The simulated tool: follows the commanded tip at most at the scene's tool speed limit in
    // simulated time, so a server that runs slower than real time (or a jumping device) never
    // drives the tool through the tissue within one tick.
    Vec3 proxy = Vec3::Zero();
    ContactResult result;
  };
  std::map<std::uint32_t, Instrument> instruments;
  std::vector<std::int32_t> surface_nodes;

  proto::Participant participant;
  proto::Reader commands, sessions;
  proto::Writer forces, scene_state, telemetry;
  std::unique_ptr<MeshPublisher> mesh_publisher;  // its own thread; after the writers it uses
  std::uint64_t rejected = 0;

  explicit Impl(const SceneSpec& s)
      : scene(s),
        participant(s.domain_id),
        commands(participant, proto::Stream::instrument_command),
        sessions(participant, proto::Stream::session_request),
        forces(participant, proto::Stream::force_feedback),
        scene_state(participant, proto::Stream::scene_state),
        telemetry(participant, proto::Stream::telemetry) {
    mesh = std::make_shared<TetMesh>(read_tet_mesh(s.mesh));
    for (int k = 0; k < s.refine; ++k) *mesh = refine_uniform(*mesh);
    scale_mesh(*mesh, s.scale_m_per_unit);
    const Material material = read_material_file(s.material);
    Mat6 D = material.elasticity;
    GpsViscoelasticity ve;
    if (material.viscoelasticity) {
      const ViscoelasticSetup setup = make_viscoelastic(material.elasticity, *material.viscoelasticity, s.material);
      D = setup.unrelaxed_elasticity;
      ve = setup.gps;
    }
    model = make_force_model(s.model, mesh, {D}, s.volume_term, ve);
    bounds = bounding_box(*mesh);
    BoundaryConditions bc;
    bc.gravity_m_s2 = Vec3(0, 0, -s.gravity_m_s2);
    const int a = s.fix_axis == "x" ? 0 : s.fix_axis == "y" ? 1 : 2;
    Box slab = bounds;
    const double extent = bounds.hi[a] - bounds.lo[a];
    if (s.fix_side == "min") slab.hi[a] = bounds.lo[a] + s.fix_fraction * extent;
    else slab.lo[a] = bounds.hi[a] - s.fix_fraction * extent;
    bc.fixed_nodes = surface_nodes_in_box(*mesh, slab);
    bc.force_field = [this](std::span<const Vec3> x, std::span<Vec3> f, std::span<double> stiffness) {
      for (auto& [id, inst] : instruments) {
        if (inst.owner == 0 || !inst.has_command) {
          inst.result = {};
          continue;
        }
        const Vec3& tip = inst.proxy;
        inst.result = inst.contact->apply(tip, x, f, stiffness);
        // Grasped nodes follow the jaws through stiff springs; the tool feels their reaction.
        for (const auto& [node, offset] : inst.grasped) {
          const Vec3 pull = scene.grasp_stiffness_n_per_m * (tip + offset - x[node]);
          f[node] += pull;
          stiffness[node] += scene.grasp_stiffness_n_per_m;
          inst.result.force_on_tool -= pull;
        }
        if (!inst.grasped.empty()) inst.result.in_contact = true;
      }
    };
    const BoundarySurface boundary = extract_boundary(*mesh);
    const auto& surface = boundary.triangles;
    // Safety 0.85 < sqrt(3)/2: the instruments' springs are taken implicitly (force_field).
    integrator = std::make_unique<ExplicitIntegrator>(*model, std::vector<double>(mesh->tet_count(), material.density_kg_m3), bc,
                                                      ExplicitOptions{0.85, 0.0, s.damping_per_s, 2.0, s.global_stable_step});
    state = State::at_rest(*mesh);
    compliance = std::make_unique<ContactCompliance>(*model, std::vector<double>(mesh->tet_count(), material.density_kg_m3), bc);
    surface_nodes = boundary.nodes;
    for (const auto& spec : s.instruments)
      instruments[spec.id] = Instrument{spec, std::make_unique<ProbeContact>(surface, spec.tip_radius_m, s.contact_stiffness_n_per_m)};
    if (s.mesh_rate_hz > 0) mesh_publisher = std::make_unique<MeshPublisher>(participant, surface_topology(boundary), boundary.nodes, s.mesh_rate_hz);
    publish_scene();
  }

  /// The boundary surface with its vertices numbered in the order of boundary.nodes.
  proto::SurfaceTopology surface_topology(const BoundarySurface& boundary) const {
    proto::SurfaceTopology t;
    t.mesh_id = 1;
    t.organ_name = scene.name;
    t.vertex_count = static_cast<std::uint32_t>(boundary.nodes.size());
    std::vector<std::uint32_t> vertex_of(mesh->node_count(), 0);
    for (std::size_t k = 0; k < boundary.nodes.size(); ++k) {
      vertex_of[boundary.nodes[k]] = static_cast<std::uint32_t>(k);
      for (int d = 0; d < 3; ++d) t.rest_positions.push_back(static_cast<float>(mesh->nodes[boundary.nodes[k]][d]));
    }
    for (const auto& tri : boundary.triangles)
      for (const auto n : tri) t.triangles.push_back(vertex_of[n]);
    return t;
  }

  void publish_scene() {
    proto::Scene sc;
    sc.name = scene.name;
    sc.physics_rate_hz = scene.physics_rate_hz;
    for (const auto& [id, inst] : instruments) sc.instruments.push_back({id, inst.spec.kind == "grasper", inst.spec.tip_radius_m, inst.owner});
    sc.bounds_min = {bounds.lo.x(), bounds.lo.y(), bounds.lo.z()};
    sc.bounds_max = {bounds.hi.x(), bounds.hi.y(), bounds.hi.z()};
    scene_state.write(0, proto::encode(sc));
  }

  void take_sessions() {
    bool changed = false;
    sessions.take([&](const proto::Received& r) {
      std::string why;
      const auto req = proto::decode_session_request(r.payload, &why);
      if (!req) {
        ++rejected;
        return;
      }
      const auto it = instruments.find(req->instrument_id);
      if (it == instruments.end()) {
        ++rejected;
        return;
      }
      Instrument& inst = it->second;
      if (req->action == proto::Action::claim_instrument && inst.owner == 0) {
        inst.owner = req->client_id;
        inst.has_command = false;
        inst.last_heard_ns = proto::now_ns();
        changed = true;
      } else if (req->action == proto::Action::release_instrument && inst.owner == req->client_id) {
        inst.owner = 0;
        inst.has_command = false;
        inst.grasped.clear();
        changed = true;
      }
    });
    if (changed) publish_scene();
  }

  /// Graspers: jaws closing (opening below 0.1 rad) grasp the surface nodes within the grasp
  /// radius of the tip; opening them (above 0.2 rad, hysteresis) releases them.
  void update_grasp(Instrument& inst) {
    if (inst.spec.kind != "grasper") return;
    const Vec3& tip = inst.proxy;  // the grasped nodes follow the simulated tool
    if (inst.grasped.empty() && inst.last.jaw_opening < 0.1) {
      for (auto n : surface_nodes)
        if ((state.x[n] - tip).norm() < inst.spec.grasp_radius_m) inst.grasped.emplace_back(n, state.x[n] - tip);
    } else if (!inst.grasped.empty() && inst.last.jaw_opening > 0.2) {
      inst.grasped.clear();
    }
  }

  /// Each simulated tool moves toward its commanded tip by at most the speed limit times dt.
  void move_proxies(double dt_s) {
    const double reach = scene.max_tool_speed_m_s * dt_s;
    for (auto& [id, inst] : instruments) {
      if (!inst.has_command) continue;
      const auto& p = inst.last.tip_position;
      const Vec3 gap = Vec3(p[0], p[1], p[2]) - inst.proxy;
      const double d = gap.norm();
      inst.proxy += d <= reach ? gap : (reach / d) * gap;
    }
  }

  /// A client that died or went silent for longer than the lease loses its instrument, which is
  /// released safely (no force on the tissue from it any more).
  void release_silent(std::int64_t lease_ns, const std::function<void(const std::string&)>& status) {
    const std::int64_t now = proto::now_ns();
    bool changed = false;
    for (auto& [id, inst] : instruments)
      if (inst.owner != 0 && now - inst.last_heard_ns > lease_ns) {
        if (status) status("instrument " + std::to_string(id) + " released: client " + std::to_string(inst.owner) + " silent for more than the lease");
        inst.owner = 0;
        inst.has_command = false;
        inst.grasped.clear();  // a dead client's grasper lets go
        changed = true;
      }
    if (changed) publish_scene();
  }

  /// Commands that arrive between ticks are answered at once: the reaction at the commanded pose
  /// on the current tissue state (contact query, no step), so the round trip does not wait for
  /// the next tick. The tick then steps the tissue with the newest pose.
  void answer_new_commands(ServerStats& stats) {
    std::vector<std::uint32_t> updated;
    commands.take([&](const proto::Received& r) {
      std::string why;
      const auto c = proto::decode_command(r.payload, &why);
      if (!c) {
        ++rejected;
        return;
      }
      const auto it = instruments.find(c->instrument_id);
      if (it == instruments.end() || it->second.owner != c->client_id) {
        ++rejected;
        return;
      }
      Instrument& inst = it->second;
      inst.last_heard_ns = proto::now_ns();
      if (!inst.has_command || c->seq > inst.last.seq) {
        if (!inst.has_command) inst.proxy = Vec3(c->tip_position[0], c->tip_position[1], c->tip_position[2]);
        inst.last = *c;
        inst.has_command = true;
        update_grasp(inst);
        updated.push_back(c->instrument_id);
      }
    });
    for (auto id : updated) {
      Instrument& inst = instruments[id];
      const auto& p = inst.last.tip_position;
      const Vec3 tip(p[0], p[1], p[2]);
      inst.result = inst.contact->apply(tip, state.x, {});
      for (const auto& [node, offset] : inst.grasped) inst.result.force_on_tool -= scene.grasp_stiffness_n_per_m * (tip + offset - state.x[node]);
      if (!inst.grasped.empty()) inst.result.in_contact = true;
      publish_force(id, inst, 0, stats);
    }
  }

  void publish_force(std::uint32_t id, const Instrument& inst, std::int64_t step_time_ns, ServerStats& stats) {
    proto::Force f;
    f.instrument_id = id;
    f.client_id = inst.owner;
    f.command_seq = inst.last.seq;
    f.command_client_stamp_ns = inst.last.client_stamp_ns;
    f.server_stamp_ns = proto::now_ns();
    f.step_time_ns = step_time_ns;
    f.force = {inst.result.force_on_tool.x(), inst.result.force_on_tool.y(), inst.result.force_on_tool.z()};
    f.in_contact = inst.result.in_contact;
    f.contact_point = {inst.result.point.x(), inst.result.point.y(), inst.result.point.z()};
    f.contact_normal = {inst.result.normal.x(), inst.result.normal.y(), inst.result.normal.z()};
    f.stiffness = local_stiffness(inst.result);
    f.penetration_m = inst.result.depth_m;
    forces.write(id, proto::encode(f));
    ++stats.forces_sent;
  }

  /// The local force model's stiffness: the contact penalty in series with the tissue condensed
  /// onto the contact, along the contact normal (the contact is frictionless); the penalty alone
  /// (an upper bound) until the tissue's compliance at the contact is known.
  std::array<double, 9> local_stiffness(const ContactResult& r) {
    if (!r.in_contact || r.deepest_triangle[0] < 0) return r.stiffness;
    const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> penalty(r.stiffness.data());
    const double k_penalty = r.normal.dot(penalty * r.normal);
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const auto block = compliance->node(r.deepest_triangle[k]);
      if (!block) return r.stiffness;
      C += r.deepest_weights[k] * *block;
    }
    const double k = 1.0 / (1.0 / k_penalty + r.normal.dot(C * r.normal));
    std::array<double, 9> out;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out[3 * i + j] = k * r.normal[i] * r.normal[j];
    return out;
  }

  void publish_forces(std::int64_t step_time_ns, ServerStats& stats) {
    for (const auto& [id, inst] : instruments)
      if (inst.owner != 0 && inst.has_command) publish_force(id, inst, step_time_ns, stats);
  }
};

SimulationServer::SimulationServer(const SceneSpec& scene) : impl_(std::make_unique<Impl>(scene)) {}
SimulationServer::~SimulationServer() = default;

std::string SimulationServer::describe() const {
  char b[400];
  std::snprintf(b, sizeof b, "scene %s: %zu nodes, %zu tets, model %s, explicit step %.3g s, %zu instruments, %.0f Hz, DDS domain %u",
                impl_->scene.name.c_str(), impl_->mesh->node_count(), impl_->mesh->tet_count(), std::string(impl_->model->name()).c_str(),
                impl_->integrator->dt_s(), impl_->instruments.size(), impl_->scene.physics_rate_hz, impl_->scene.domain_id);
  return b;
}

ServerStats SimulationServer::run(const std::atomic<bool>& stop, double duration_s, const std::function<void(const std::string&)>& status) {
  Impl& s = *impl_;
  ServerStats stats;
  using clock = std::chrono::steady_clock;
  const auto period = std::chrono::nanoseconds(static_cast<long long>(1e9 / s.scene.physics_rate_hz));
  const auto start = clock::now();
  auto next = start;
  auto last_report = start;
  std::vector<double> step_us, jitter_us;
  std::uint64_t ticks_at_report = 0;
  while (!stop.load()) {
    const auto tick_start = clock::now();
    jitter_us.push_back(std::chrono::duration<double, std::micro>(tick_start - next).count());
    s.take_sessions();
    s.answer_new_commands(stats);
    s.release_silent(500'000'000, status);  // the DDS liveliness lease of the command stream
    s.move_proxies(1.0 / s.scene.physics_rate_hz);
    const auto t0 = clock::now();
    try {
      s.integrator->advance(s.state, 1.0 / s.scene.physics_rate_hz);
      s.sim_time_s += 1.0 / s.scene.physics_rate_hz;
    } catch (const SimulationError& e) {
      // Keep serving, but never stay stuck: the same input would fail again from the rolled-back
      // state, so the organ goes back to rest (memory variables relaxed) and graspers let go.
      s.state = State::at_rest(*s.mesh);
      for (auto& [id, inst] : s.instruments) inst.grasped.clear();
      ++stats.physics_resets;
      if (status) status(std::string("physics: ") + e.what() + "; organ reset to rest");
    }
    const auto t1 = clock::now();
    step_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    s.publish_forces(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count(), stats);
    if (s.mesh_publisher) s.mesh_publisher->offer(s.state.x, s.sim_time_s, proto::now_ns());
    ++stats.ticks;
    if (t1 - last_report >= std::chrono::seconds(1)) {
      const double seconds = std::chrono::duration<double>(t1 - last_report).count();
      stats.rate_hz = static_cast<double>(stats.ticks - ticks_at_report) / seconds;
      stats.step_p50_us = percentile(step_us, 0.5);
      stats.step_p99_us = percentile(step_us, 0.99);
      stats.step_max_us = *std::max_element(step_us.begin(), step_us.end());
      stats.jitter_p99_us = percentile(jitter_us, 0.99);
      stats.rejected = s.rejected;
      if (s.mesh_publisher) {
        stats.mesh_frames = s.mesh_publisher->frames_published();
        stats.mesh_frames_skipped = s.mesh_publisher->frames_skipped();
      }
      s.telemetry.write(0, proto::encode(proto::TelemetryReport{proto::now_ns(), stats.ticks, stats.overruns, stats.rejected, stats.rate_hz,
                                                                stats.step_p50_us, stats.step_p99_us, stats.step_max_us, stats.jitter_p99_us}));
      if (status) {
        char line[400];
        int owned = 0;
        double fmax = 0;
        for (const auto& [id, inst] : s.instruments) {
          owned += inst.owner != 0;
          fmax = std::max(fmax, inst.result.force_on_tool.norm());
        }
        std::snprintf(line, sizeof line, "%.0f Hz physics, step p50 %.0f us p99 %.0f us max %.0f us, jitter p99 %.0f us, overruns %llu, "
                      "%d instruments claimed, |F| %.3f N, rejected %llu, physics resets %llu, mesh frames %llu (%llu skipped)",
                      stats.rate_hz, stats.step_p50_us, stats.step_p99_us, stats.step_max_us, stats.jitter_p99_us,
                      static_cast<unsigned long long>(stats.overruns), owned, fmax, static_cast<unsigned long long>(stats.rejected),
                      static_cast<unsigned long long>(stats.physics_resets), static_cast<unsigned long long>(stats.mesh_frames),
                      static_cast<unsigned long long>(stats.mesh_frames_skipped));
        status(line);
      }
      step_us.clear();
      jitter_us.clear();
      last_report = t1;
      ticks_at_report = stats.ticks;
    }
    if (duration_s > 0 && std::chrono::duration<double>(t1 - start).count() >= duration_s) break;
    next += period;
    const auto now = clock::now();
    if (now > next) {
      ++stats.overruns;  // missed the deadline: do not try to catch up with a burst
      next = now;
    } else {
      // Until the next tick: answer commands as they arrive.
      while (clock::now() < next) {
        if (s.commands.wait(next - clock::now())) s.answer_new_commands(stats);
      }
    }
  }
  stats.rejected = s.rejected;
  if (s.mesh_publisher) {
    stats.mesh_frames = s.mesh_publisher->frames_published();
    stats.mesh_frames_skipped = s.mesh_publisher->frames_skipped();
  }
  return stats;
}

}  // namespace viscera::runtime
