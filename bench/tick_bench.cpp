// One physics tick of a bundled scene as viscera-server runs it: the scene's organ (model, mass
// scaling, fixed slab) advanced by one tick, 1 / physics_rate_hz, in the integrator's equal
// sub-steps, with the internal forces on one thread and on the scene's threads. No DDS, no
// instruments: what the tick costs before anything else shares the cores (docs/PERFORMANCE.md).
// Run: build/bench/tick_bench [--benchmark_filter=liver-12k]
#include <cmath>
#include <cstdint>
#include <string>

#include <benchmark/benchmark.h>

#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/scene_file.hpp"

namespace {

using namespace viscera;

void tick(benchmark::State& st, const std::string& scene_name, int threads) {
  runtime::SceneSpec scene = runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_name + ".json");
  scene.physics_threads = threads;
  const auto organ = runtime::build_organ(scene);
  // The contact compliance factorises on a worker thread: wait for it, so it does not share the cores.
  if (organ->mesh->node_count() > 0) organ->compliance->wait_node(0);
  tissue::State state = tissue::State::at_rest(*organ->mesh);
  // A small velocity field (1 mm/s), so that the organ moves and the memory variables change.
  for (std::size_t i = 0; i < state.v.size(); ++i)
    state.v[i] = 1e-3 * tissue::Vec3(std::sin(0.7 * static_cast<double>(i)), std::cos(1.3 * static_cast<double>(i)), 0.0);
  const double dt = 1.0 / scene.physics_rate_hz;
  long sub_steps = 0;
  for (auto _ : st) sub_steps = organ->integrator->advance(state, dt);
  st.counters["sub_steps"] = static_cast<double>(sub_steps);
  st.counters["tets"] = static_cast<double>(organ->mesh->tet_count());
  st.counters["tick_budget_us"] = 1e6 * dt;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (const std::string scene : {"liver", "liver-12k", "liver-96k"})
    for (const int threads : {1, 2})
      benchmark::RegisterBenchmark(("Tick/" + scene + "/threads:" + std::to_string(threads)).c_str(), tick, scene, threads)
          ->Unit(benchmark::kMicrosecond)
          ->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
}
