// Cutting (docs/CUTTING.md): one scalpel stroke across the liver at 1 kHz, 0.2 m/s, a 6 cm blade  // SPDX-License-Identifier: Apache-2.0
// drawn through the organ's middle, on the 1.5k and the 12k liver in one run.
//  - BM_CutStroke: each tick's sweep, the topology (MeshCutter::cut) and then the organ's force
//    model following it in place (GpsModel::follow_edit, the scenes' viscoelastic model, its
//    memory carried); counters give the time per sweep (median, p99, max) and the most
//    tetrahedra one sweep made.
//  - BM_RebuildAfterCut: the alternative, the model built again for the whole cut organ.
//  - BM_ServerSweep: the same stroke through the server's organ of the bundled scene (liver.json,
//    liver-12k.json) as a scalpel cuts it between ticks (runtime::cut_organ): the topology, the
//    model, the explicit integrator (masses, the step rule), the boundary surface and the
//    contacts' surface, everything a tick pays for a sweep.
// Run: build/bench/cut_bench (or bench/run.sh, which runs every benchmark).
#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>
#include <set>

#include <benchmark/benchmark.h>

#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/organ_cutting.hpp"
#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/boundary_conditions.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/refinement.hpp"

using namespace viscera::tissue;

namespace {

const TetMesh& liver(int level) {
  static const std::vector<TetMesh> meshes = [] {
    TetMesh base = read_tet_mesh(std::string(VISCERA_DATA_DIR) + "/meshes/liver2.msh");
    scale_mesh(base, 0.08);
    return std::vector<TetMesh>{base, refine_uniform(base)};
  }();
  return meshes[static_cast<std::size_t>(level)];
}

// The blade: 6 cm along the organ's vertical axis through its centre, drawn along x at 0.2 mm per
// tick (0.2 m/s at 1 kHz) from one side of the box to the other.
struct Stroke {
  Vec3 centre, travel;
  double half_blade = 0.03, step = 2e-4;
  int ticks = 0;
  /// `scale`: the blade's length and its travel per tick times this (a sweep's patch times its
  /// square), along the same line.
  explicit Stroke(const TetMesh& m, double scale = 1.0) : half_blade(0.03 * scale), step(2e-4 * scale) {
    const Box b = bounding_box(m);
    centre = 0.5 * (b.lo + b.hi);
    travel = Vec3(b.hi.x() - b.lo.x() + 0.02, 0, 0);
    ticks = static_cast<int>(travel.x() / step);
  }
  BladeSweep sweep(int k) const {
    const Vec3 start = centre - 0.5 * travel;
    const Vec3 p0 = start + travel * (static_cast<double>(k) / ticks), p1 = start + travel * (static_cast<double>(k + 1) / ticks);
    const Vec3 h(0.2 * half_blade, 0, half_blade);  // a blade tilted in its plane
    return {p0 - h, p0 + h, p1 - h, p1 + h};
  }
};

GpsOptions scene_options() {  // as the bundled liver scenes: energy GPS, volume term, 3 memory variables
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.5;
  o.mechanisms.viscous.omega_rad_s = {0.2, 6.3, 200.0};
  o.mechanisms.viscous.shear_weight = {0.1, 0.1, 0.1};
  o.mechanisms.viscous.bulk_weight = {0.0, 0.0, 0.0};
  return o;
}

const Mat6& material() {
  static const Mat6 D = elasticity_matrix(IsotropicElasticity{5e3, 0.45});
  return D;
}

void BM_CutStroke(benchmark::State& state) {
  const TetMesh& original = liver(static_cast<int>(state.range(0)));
  const Stroke stroke(original);
  std::vector<double> topology, total;
  std::size_t most_tets = 0, tets_after = 0, cut_parents = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto m = std::make_shared<TetMesh>(original);
    MeshCutter cutter(*m);
    GpsModel model(m, {material()}, {}, scene_options());
    std::vector<double> memory(model.memory_size(), 0.0);
    std::vector<Vec3> x = m->nodes;
    std::vector<std::int32_t> root(m->tets.size());  // the tetrahedron of the organ each comes from
    std::iota(root.begin(), root.end(), 0);
    std::set<std::int32_t> ever_cut;
    model.reserve_elements(2 * m->tets.size());  // as a server would when it loads a scene to cut
    memory.reserve(model.memory_size_for(2 * m->tets.size()));
    m->tets.reserve(2 * m->tets.size());
    m->nodes.reserve(2 * m->nodes.size());
    x.reserve(2 * m->nodes.size());
    state.ResumeTiming();
    for (int k = 0; k < stroke.ticks; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const CutChange c = cutter.cut(stroke.sweep(k), x, 0);
      const auto t1 = std::chrono::steady_clock::now();
      extend_nodal(c, x);
      if (c.topology_changed()) model.follow_edit(c.edit(), memory);
      const auto t2 = std::chrono::steady_clock::now();
      topology.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
      total.push_back(std::chrono::duration<double, std::micro>(t2 - t0).count());
      most_tets = std::max(most_tets, c.origin.size() - c.tets_before);
      for (std::size_t e = c.tets_before; e < c.origin.size(); ++e) ever_cut.insert(root[static_cast<std::size_t>(c.origin[e])]);
      for (const auto& [e, tet] : c.replaced) ever_cut.insert(root[static_cast<std::size_t>(e)]);
      for (std::size_t e = c.tets_before; e < c.origin.size(); ++e) root.push_back(root[static_cast<std::size_t>(c.origin[e])]);
    }
    tets_after = m->tets.size();
    cut_parents = ever_cut.size();
  }
  const auto quantile = [](std::vector<double>& v, double q) {
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
  };
  state.counters["sweeps"] = stroke.ticks;
  state.counters["cut_p50_us"] = quantile(topology, 0.5);
  state.counters["cut_p99_us"] = quantile(topology, 0.99);
  state.counters["with_model_p50_us"] = quantile(total, 0.5);
  state.counters["with_model_p99_us"] = quantile(total, 0.99);
  state.counters["with_model_max_us"] = total.back();
  state.counters["most_new_tets_per_sweep"] = static_cast<double>(most_tets);
  state.counters["tets_before"] = static_cast<double>(original.tets.size());
  state.counters["tets_after"] = static_cast<double>(tets_after);
  // The organ's tetrahedra the stroke changed, and how many each became (Bielser's split: 17).
  state.counters["cut_tets"] = static_cast<double>(cut_parents);
  state.counters["pieces_per_cut_tet"] = static_cast<double>(tets_after - original.tets.size() + cut_parents) / static_cast<double>(cut_parents);
}

void BM_RebuildAfterCut(benchmark::State& state) {
  TetMesh m = liver(static_cast<int>(state.range(0)));
  const Stroke stroke(m);
  MeshCutter cutter(m);
  std::vector<Vec3> x = m.nodes;
  for (int k = 0; k < stroke.ticks; ++k) extend_nodal(cutter.cut(stroke.sweep(k), x, 0), x);
  const auto mesh = std::make_shared<TetMesh>(m);
  for (auto _ : state) {
    GpsModel model(mesh, {material()}, {}, scene_options());
    benchmark::DoNotOptimize(model);
    std::vector<double> masses = lumped_masses(m, 1000.0);
    benchmark::DoNotOptimize(masses.data());
  }
  state.counters["tets"] = static_cast<double>(m.tets.size());
}

void BM_ServerSweep(benchmark::State& state) {
  // scene_level 2: the 12k liver cut by a blade half as long drawn half as far per tick, so that
  // each sweep's patch is a quarter of the 1.5k's and crosses about as many of the 12k's
  // tetrahedra (their edges are half as long) as the 1.5k's sweep crosses of its own: the same cut
  // region, a mesh eight times larger.
  const std::string scene_file = state.range(0) == 0 ? "liver.json" : "liver-12k.json";
  const double scale = state.range(0) == 2 ? 0.5 : 1.0;
  std::vector<double> t;
  std::size_t tets_before = 0, tets_after = 0, generation = 0;
  double added_kg = 0, organ_kg = 0;
  std::size_t replaced = 0, changes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const auto organ = viscera::runtime::build_organ(viscera::runtime::read_scene_file(std::string(VISCERA_DATA_DIR) + "/scenes/" + scene_file));
    State s = State::at_rest(*organ->mesh);
    organ->integrator->step(s);  // the memory variables in use, as in a running server
    viscera::runtime::reserve_for_cuts(*organ, s);
    // A server cuts an organ whose contact compliance was factorised long before; here the worker
    // that factorises it would share the cores with the sweeps timed.
    organ->compliance->wait_settled();
    const Stroke stroke(*organ->mesh, scale);
    tets_before = organ->mesh->tet_count();
    for (const double m : organ->integrator->masses()) organ_kg += m;
    state.ResumeTiming();
    for (int k = 0; k < stroke.ticks; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto out = viscera::runtime::cut_organ(*organ, stroke.sweep(k), s, 0);
      t.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
      added_kg += out.added_mass_kg;
      replaced += out.tets_cut;
      changes += out.topology_changed;
    }
    tets_after = organ->mesh->tet_count();
    generation = organ->topology_generation;
  }
  std::sort(t.begin(), t.end());
  state.counters["sweeps"] = static_cast<double>(t.size());
  state.counters["sweep_p50_us"] = t[t.size() / 2];
  state.counters["sweep_p99_us"] = t[static_cast<std::size_t>(0.99 * static_cast<double>(t.size() - 1))];
  state.counters["sweep_max_us"] = t.back();
  state.counters["tets_before"] = static_cast<double>(tets_before);
  state.counters["tets_after"] = static_cast<double>(tets_after);
  state.counters["surface_changes"] = static_cast<double>(generation);
  state.counters["inertia_added_pct"] = 100.0 * added_kg / organ_kg;
  state.counters["tets_cut_per_change"] = static_cast<double>(replaced) / static_cast<double>(std::max<std::size_t>(changes, 1));
}

}  // namespace

BENCHMARK(BM_ServerSweep)->Arg(0)->Arg(1)->Arg(2)->ArgName("scene_level")->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_CutStroke)->Arg(0)->Arg(1)->ArgName("liver_level")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_RebuildAfterCut)->Arg(0)->Arg(1)->ArgName("liver_level")->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
