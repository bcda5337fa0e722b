// One physics tick of a bundled scene as viscera-server runs it: the scene's organ (model, mass  // SPDX-License-Identifier: Apache-2.0
// scaling, fixed slab) advanced by one tick, 1 / physics_rate_hz, in the integrator's equal
// sub-steps, with the internal forces on one thread and on the scene's threads. No DDS, no
// instruments: what the tick costs before anything else shares the cores (docs/PERFORMANCE.md).
// Elements/..., NodesOnly/... and Serial/...: the element loop alone, the tick without it, and the
// tick without it but with the force threads' hand-over and buffers (the serial share).
// Material/...: the same tick with the organ switched to each mechanism the lab can hand over.
// Contact/...: the tick with two probes pressed into the organ, by the penalty contact or the
// proxy, against none.
// Run: build/bench/tick_bench [--benchmark_filter=liver-12k]; VISCERA_TICK_SCENE=FILE adds Tick/... of that scene file.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "viscera/common/json_input.hpp"
#include "viscera/runtime/command_responder.hpp"
#include "viscera/runtime/contact_proxy.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/parallel_forces.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace {

using namespace viscera;

/// Ticks of `organ` at `rate_hz` from its rest shape scaled by `stretch`, with a small velocity
/// field (1 mm/s), so that the organ moves and the memory variables change.
void run_ticks(benchmark::State& st, const runtime::Organ& organ, double rate_hz, double stretch) {
  // The contact compliance factorises on a worker thread: wait for it, so it does not share the cores.
  if (organ.mesh->node_count() > 0) organ.compliance->wait_node(0);
  tissue::State state = tissue::State::at_rest(*organ.mesh);
  for (std::size_t i = 0; i < state.v.size(); ++i) {
    state.x[i] *= stretch;
    state.v[i] = 1e-3 * tissue::Vec3(std::sin(0.7 * static_cast<double>(i)), std::cos(1.3 * static_cast<double>(i)), 0.0);
  }
  long sub_steps = 0;
  for (auto _ : st) sub_steps = organ.integrator->advance(state, 1.0 / rate_hz);
  st.counters["sub_steps"] = static_cast<double>(sub_steps);
  st.counters["tets"] = static_cast<double>(organ.mesh->tet_count());
  st.counters["nodes"] = static_cast<double>(organ.mesh->node_count());
}

/// The element loop of `scene`'s organ alone: one evaluation of its internal forces over every
/// element on one thread, memory advanced, at the rest shape stretched by 0.1%. A tick on one
/// thread is its sub-steps times this plus what is serial (the tick's serial share).
void elements(benchmark::State& st, const std::string& scene_name) {
  const auto organ = runtime::build_organ(runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json"));
  if (organ->mesh->node_count() > 0) organ->compliance->wait_node(0);
  std::vector<tissue::Vec3> x = organ->mesh->nodes, f(x.size(), tissue::Vec3::Zero());
  for (auto& p : x) p *= 1.001;
  std::vector<double> memory(organ->model->memory_size(), 0.0);
  for (auto _ : st) organ->model->add_forces(x, f, tissue::MemoryUpdate{memory, memory, 1e-3});
  benchmark::DoNotOptimize(f.data());
  st.counters["tets"] = static_cast<double>(organ->mesh->tet_count());
}

void tick(benchmark::State& st, const std::string& scene_name, int threads) {
  // A bundled scene by name, or any scene file (VISCERA_TICK_SCENE).
  runtime::SceneSpec scene =
      runtime::read_scene_file(scene_name.ends_with(".json") ? scene_name : std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json");
  scene.physics_threads = threads;
  run_ticks(st, *runtime::build_organ(scene), scene.physics_rate_hz, 1.0);
  st.counters["tick_budget_us"] = 1e6 / scene.physics_rate_hz;
}

/// The tick of `scene` on `threads` without its element loop: the integrator's force evaluation
/// replaced by one that adds nothing, so what is timed is the rest of the sub-steps (the forces'
/// initial values, the nodes' update and what the step keeps for its roll-back).
void nodes_only(benchmark::State& st, const std::string& scene_name, int threads) {
  runtime::SceneSpec scene = runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json");
  scene.physics_threads = threads;
  const auto organ = runtime::build_organ(scene);
  organ->integrator->set_force_evaluation(
      [](std::span<const tissue::Vec3>, std::span<tissue::Vec3>, const tissue::MemoryUpdate&) { return tissue::ForceStats{}; });
  run_ticks(st, *organ, scene.physics_rate_hz, 1.0);
}

/// A model with the elements of `model` that adds nothing: ParallelForces over it does all it does
/// for the real one (the chunks' hand-over, the clearing and the sum of their buffers) but the
/// elements' work.
class NoElementWork final : public tissue::ForceModel {
 public:
  NoElementWork(std::shared_ptr<const tissue::TetMesh> mesh, const tissue::ForceModel& model) : ForceModel(std::move(mesh)), model_(model) {}
  std::string_view name() const override { return "no-element-work"; }
  tissue::ForceStats add_forces(std::span<const tissue::Vec3>, std::span<tissue::Vec3>) const override { return {}; }
  tissue::ForceStats add_forces(std::span<const tissue::Vec3>, std::span<tissue::Vec3>, const tissue::MemoryUpdate&,
                                tissue::ElementPart) const override {
    return {};
  }
  std::pair<std::size_t, std::size_t> part_elements(tissue::ElementPart part) const override { return model_.part_elements(part); }
  double energy(std::span<const tissue::Vec3>) const override { return 0.0; }
  tissue::Mat12 element_tangent(std::span<const tissue::Vec3>, std::size_t) const override { return tissue::Mat12::Zero(); }

 private:
  const tissue::ForceModel& model_;
};

/// The tick of `scene` on `threads` with the organ's force threads evaluating a model that adds
/// nothing: all of the tick but its element loops, the force threads' hand-over, clearing and sum
/// of their buffers included. On one thread, divided by the tick, the tick's serial share measured
/// directly. `chunks`: as many as the server cuts on 16 threads, say; `summed_first`: the buffers
/// summed by the calling thread before the node loop instead of in its ranges (as before 2026-11-29).
void serial(benchmark::State& st, const std::string& scene_name, int threads, int chunks, bool summed_first) {
  runtime::SceneSpec scene = runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json");
  scene.physics_threads = threads;
  const auto organ = runtime::build_organ(scene);
  const NoElementWork none(organ->mesh, *organ->model);
  runtime::ParallelForces forces(none, threads, chunks);
  organ->integrator->set_force_evaluation(
      [&forces, summed_first](std::span<const tissue::Vec3> x, std::span<tissue::Vec3> f, const tissue::MemoryUpdate& m) {
        return summed_first ? forces(x, f, m) : forces.evaluate_leaving_sums(x, f, m);
      });
  organ->integrator->set_node_loop(
      [&forces](std::size_t n, const std::function<void(std::size_t, std::size_t)>& update) { forces.for_ranges(n, update); });
  run_ticks(st, *organ, scene.physics_rate_hz, 1.0);
}

/// The tick of `scene` with its organ switched to another material (as viscera-control material
/// --file does): the cost of each mechanism the lab can hand over. The variants share the unrelaxed
/// modulus (5 kPa, nu 0.45), so they take the same sub-steps and their ratios are the mechanisms'
/// own cost; the lab's titin files run with their own moduli and steps.
struct MaterialVariant {
  const char* name;
  std::string viscoelasticity;  ///< the material file's "viscoelasticity" object, or empty; "@file" names a file of data/materials
};

const std::vector<MaterialVariant>& material_variants() {
  static const std::vector<MaterialVariant> v{
      {"elastic", ""},
      {"spectrum-1", R"({"model": "relaxation_spectrum", "relaxation_times_s": [1], "relaxation_weights": [0.3]})"},
      {"spectrum-3", R"({"model": "relaxation_spectrum", "relaxation_times_s": [0.1, 1, 10], "relaxation_weights": [0.2, 0.2, 0.2]})"},
      {"spectrum-5", R"({"model": "relaxation_spectrum", "relaxation_times_s": [0.01, 0.1, 1, 10, 1000],
                         "relaxation_weights": [0.15, 0.15, 0.15, 0.15, 0.15]})"},
      {"spectrum-5+stiffening", R"({"model": "relaxation_spectrum", "relaxation_times_s": [0.01, 0.1, 1, 10, 1000],
                         "relaxation_weights": [0.15, 0.15, 0.15, 0.15, 0.15], "qlv_stiffening": 5, "qlv_form": "energy",
                         "qlv_shape": "odd_exponential"})"},
      {"spectrum-5+stiffening+asymmetry", R"({"model": "relaxation_spectrum", "relaxation_times_s": [0.01, 0.1, 1, 10, 1000],
                         "relaxation_weights": [0.15, 0.15, 0.15, 0.15, 0.15], "qlv_stiffening": 5, "qlv_form": "energy",
                         "qlv_shape": "odd_exponential", "compression_ratio": 2})"},
      {"spectrum-5+softening", R"({"model": "relaxation_spectrum", "relaxation_times_s": [0.01, 0.1, 1, 10, 1000],
                         "relaxation_weights": [0.15, 0.15, 0.15, 0.15, 0.15], "softening_d": 0.3})"},
      {"constant-q-3", R"({"model": "constant_q", "shear_q": 4.8, "band_hz": [0.01, 10], "mechanisms": 3, "reference_frequency_hz": 2})"},
      {"titin-fitted", "@titin-fitted.json"},
      {"titin-linear", "@titin-linear.json"}};
  return v;
}

void tick_with_material(benchmark::State& st, const std::string& scene_name, const MaterialVariant& variant) {
  const runtime::SceneSpec scene = runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json");
  const auto built = runtime::build_organ(scene);
  protocol::MaterialChange change;
  change.file_name = variant.name;
  if (variant.viscoelasticity.starts_with("@"))
    change.file_text = common::read_text_file(std::string(VISCERA_DATA_DIR) + "/materials/" + variant.viscoelasticity.substr(1), 1 << 20);
  else
    change.file_text = R"({"name": ")" + std::string(variant.name) +
                       R"(", "density_kg_m3": 1060, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 5000, "poisson_ratio": 0.45})" +
                       (variant.viscoelasticity.empty() ? "" : ", \"viscoelasticity\": " + variant.viscoelasticity) + "}";
  // A small stretch, so that stiffening, asymmetry and softening act.
  run_ticks(st, *runtime::rebuild_with_material(*built, change, scene.physics_rate_hz), scene.physics_rate_hz, 1.002);
}

/// How two probes (6 mm tips, 3 cm apart) touch `scene`'s organ in Contact/...: none, the penalty
/// contact, or the contact proxy (docs/HAPTICS.md).
enum class Touch { none, penalty, proxy };

/// The tick of `scene` on one thread with two probes pressed 8 mm into its top and held there:
/// the contact's cost side by side with none (the scene's contact stiffness, dashpot, friction).
void contact_tick(benchmark::State& st, const std::string& scene_name, Touch touch) {
  const runtime::SceneSpec scene = runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json");
  const auto organ = runtime::build_organ(scene);
  if (organ->mesh->node_count() > 0) organ->compliance->wait_node(0);
  runtime::InstrumentSpec tip;
  tip.tip_radius_m = 0.006;
  const double dt = 1.0 / scene.physics_rate_hz;
  const tissue::Box& b = organ->bounds;
  const tissue::Vec3 centre(0.5 * (b.lo.x() + b.hi.x()), 0.5 * (b.lo.y() + b.hi.y()), b.hi.z() + 0.002);
  std::vector<tissue::Vec3> goals = {centre - tissue::Vec3(0.015, 0, 0), centre + tissue::Vec3(0.015, 0, 0)}, velocity(2, tissue::Vec3::Zero());
  std::vector<runtime::ContactProxy> proxies(2, runtime::ContactProxy(organ->contact_surface, runtime::proxy_parameters(scene, tip)));
  std::vector<runtime::ProbeContact> penalties(
      2, runtime::ProbeContact(organ->contact_surface, tip.tip_radius_m, scene.contact_stiffness_n_per_m, 0.02, scene.contact_damping_s_per_m));
  std::vector<bool> touching(2, false);
  std::vector<double> touched_z(2, NAN);
  bool timing = false;
  organ->integrator->boundary_conditions().force_field = [&](const tissue::BoundaryConditions::FieldEvaluation& e) {
    for (std::size_t k = 0; k < 2; ++k) {
      if (touch == Touch::none) {  // the penalty's geometry only, for the press to find the surface
        if (!timing) touching[k] = penalties[k].query(goals[k], e.x).in_contact;
        continue;
      }
      const auto r = touch == Touch::proxy ? proxies[k].apply(goals[k], velocity[k], e) : penalties[k].apply(goals[k], velocity[k], e);
      touching[k] = r.in_contact || (touch == Touch::proxy && proxies[k].anchored());
    }
  };
  tissue::State state = tissue::State::at_rest(*organ->mesh);
  long sub_steps = 0;
  const auto step = [&] {
    if (touch == Touch::proxy)
      for (std::size_t k = 0; k < 2; ++k) proxies[k].track(goals[k], state.x, dt);
    sub_steps = organ->integrator->advance(state, dt);
  };
  for (int t = 0; t < 20000; ++t) {  // down at 1 cm/s to 8 mm past each probe's first touch, then 0.2 s held
    bool moving = false;
    for (std::size_t k = 0; k < 2; ++k) {
      if (std::isnan(touched_z[k]) && touching[k]) touched_z[k] = goals[k].z();
      const double target = std::isnan(touched_z[k]) ? b.lo.z() : touched_z[k] - 0.008;
      const double move = std::max(-1e-5 * dt / 1e-3, target - goals[k].z());
      goals[k].z() += move;
      velocity[k] = tissue::Vec3(0, 0, move / dt);
      moving = moving || move != 0.0;
    }
    step();
    if (!moving && t > 200) break;
  }
  for (int t = 0; t < 200; ++t) step();
  velocity.assign(2, tissue::Vec3::Zero());
  timing = true;
  for (auto _ : st) step();
  st.counters["sub_steps"] = static_cast<double>(sub_steps);
  st.counters["tets"] = static_cast<double>(organ->mesh->tet_count());
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (const std::string scene : {"liver", "liver-12k", "liver-96k"}) {
    benchmark::RegisterBenchmark(("Elements/" + scene).c_str(), elements, scene)->Unit(benchmark::kMicrosecond)->UseRealTime();
    for (const int threads : {1, 2})
      benchmark::RegisterBenchmark(("NodesOnly/" + scene + "/threads:" + std::to_string(threads)).c_str(), nodes_only, scene, threads)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
    for (const int threads : {1, 2})
      benchmark::RegisterBenchmark(("Serial/" + scene + "/threads:" + std::to_string(threads)).c_str(), serial, scene, threads,
                                   std::max(runtime::kForceChunks, threads), false)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
    for (const int threads : {1, 2})
      benchmark::RegisterBenchmark(("Tick/" + scene + "/threads:" + std::to_string(threads)).c_str(), tick, scene, threads)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  }
  // Tick/FILE/...: a scene of the user's (a patient's organ from viscera-mesh) beside the bundled ones.
  if (const char* extra = std::getenv("VISCERA_TICK_SCENE"); extra && *extra)
    for (const int threads : {1, 2})
      benchmark::RegisterBenchmark(("Tick/" + std::filesystem::path(extra).stem().string() + "/threads:" + std::to_string(threads)).c_str(), tick,
                                   std::string(extra), threads)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  // The hand-over and the buffers with the 16 chunks of 16 threads, on one and two: their sum in
  // the node loop's ranges against on the calling thread before it.
  for (const bool summed_first : {false, true})
    for (const int threads : {1, 2})
      benchmark::RegisterBenchmark(
          ((summed_first ? "SerialSummedFirst" : "Serial") + std::string("/liver-96k/chunks:16/threads:") + std::to_string(threads)).c_str(), serial,
          "liver-96k", threads, 16, summed_first)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  for (const std::string scene : {"liver", "liver-12k"})
    for (const MaterialVariant& v : material_variants())
      benchmark::RegisterBenchmark(("Material/" + std::string(v.name) + "/" + scene).c_str(), tick_with_material, scene, v)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  for (const std::string scene : {"liver", "liver-12k"})
    for (const auto& [name, touch] : {std::pair{"none", Touch::none}, std::pair{"penalty", Touch::penalty}, std::pair{"proxy", Touch::proxy}})
      benchmark::RegisterBenchmark(("Contact/" + scene + "/" + name).c_str(), contact_tick, scene, touch)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
}
