// Force evaluation and a full explicit step for liver2 at three refinement levels, for every model,  // SPDX-License-Identifier: Apache-2.0
// in one run; plus the machine's streaming read bandwidth for the same working-set sizes, so the
// distance to the memory limit is visible (docs/PERFORMANCE.md). Run: bench/run.sh
#include <algorithm>
#include <map>
#include <memory>
#include <numeric>

#include <benchmark/benchmark.h>

#include "viscera/tissue/element/ball_strain.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/refinement.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

using namespace viscera::tissue;

namespace {

struct Level {
  std::string name;
  std::shared_ptr<TetMesh> mesh;
};

const std::vector<Level>& levels() {
  static const std::vector<Level> l = [] {
    auto base = std::make_shared<TetMesh>(read_tet_mesh(std::string(VISCERA_DATA_DIR) + "/meshes/liver2.msh"));
    scale_mesh(*base, 0.08);
    auto l1 = std::make_shared<TetMesh>(refine_uniform(*base));
    auto l2 = std::make_shared<TetMesh>(refine_uniform(*l1));
    return std::vector<Level>{{"liver2_1.5k", base}, {"liver2_12k", l1}, {"liver2_96k", l2}};
  }();
  return l;
}

// A deformed, rotated configuration: every model does its full work (polar decompositions
// iterate, edge lengths change).
std::vector<Vec3> deformed(const TetMesh& mesh) {
  const Mat3 R = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  std::vector<Vec3> x = mesh.nodes;
  for (auto& p : x) p = R * Vec3(p.x() * 1.05, p.y() * 0.97, p.z() + 0.5 * p.x() * p.x());
  return x;
}

const Mat6& material() {
  static const Mat6 D = elasticity_matrix(IsotropicElasticity{5e3, 0.45});
  return D;
}

// "gps_visco3": the paper-form GPS with 3 constant-Q memory variables (Q = 4.8 in shear over
// 0.01-10 Hz, bulk elastic), as data/materials/liver-viscoelastic.json. "scene": what the bundled
// liver scenes run (data/scenes/liver*.json): the energy-consistent form with the same memory and
// half the bulk stiffness in the signed-volume term; "scene_large_strain": the same material on
// the large-strain GPS (its memory relaxes the backbone's deviatoric stress).
std::unique_ptr<ForceModel> make_model(const std::string& name, const Level* level) {
  if (name == "gps_visco3" || name == "scene" || name == "scene_large_strain") {
    const ViscoelasticSetup ve = make_viscoelastic(material(), ViscoelasticSpec{});  // bulk elastic
    if (name == "scene") return make_force_model("gps_energy", level->mesh, {ve.unrelaxed_elasticity}, 0.5, ve.gps);
    if (name == "scene_large_strain") return make_force_model("gps_large_strain", level->mesh, {ve.unrelaxed_elasticity}, 0.0, ve.gps);
    return make_force_model("gps", level->mesh, {ve.unrelaxed_elasticity}, 0.0, ve.gps);
  }
  return make_force_model(name, level->mesh, {material()});
}

void count_tets(benchmark::State& st, const Level* level) {
  const double tets = static_cast<double>(level->mesh->tet_count());
  st.counters["tets"] = tets;
  st.counters["tet_updates_per_s"] = benchmark::Counter(tets * static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
  st.counters["ns_per_tet"] =
      benchmark::Counter(tets * static_cast<double>(st.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void force(benchmark::State& st, const std::string& model_name, const Level* level) {
  const auto model = make_model(model_name, level);
  const auto x = deformed(*level->mesh);
  std::vector<Vec3> f(x.size());
  for (auto _ : st) {
    std::fill(f.begin(), f.end(), Vec3::Zero());
    benchmark::DoNotOptimize(model->add_forces(x, f));
    benchmark::ClobberMemory();
  }
  count_tets(st, level);
}

void step(benchmark::State& st, const std::string& model_name, const Level* level) {
  const auto model = make_model(model_name, level);
  BoundaryConditions bc;
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  const Box b = bounding_box(*level->mesh);
  bc.fixed_nodes = nodes_in_box(*level->mesh, {Vec3(b.lo.x(), b.lo.y(), b.hi.z() - 0.2 * (b.hi.z() - b.lo.z())), b.hi});
  ExplicitIntegrator integrator(*model, std::vector<double>(level->mesh->tet_count(), 1060.0), bc, {0.9, 0.0, 5.0, 2.0});
  State s = State::at_rest(*level->mesh);
  for (int k = 0; k < 50; ++k) integrator.step(s);  // leave the rest state
  for (auto _ : st) {
    integrator.step(s);
    benchmark::ClobberMemory();
  }
  count_tets(st, level);
  st.counters["dt_s"] = integrator.dt_s();
}

// The strain at an instrument (the server computes it after every tick for each instrument in
// contact): averaged over the scene's default 2 cm about the organ's highest node, on the deformed
// configuration.
void tip_strain(benchmark::State& st, const Level* level) {
  const BallStrain ball(level->mesh, 0.02);
  const auto x = deformed(*level->mesh);
  const auto& nodes = level->mesh->nodes;
  const Vec3 top = *std::max_element(nodes.begin(), nodes.end(), [](const Vec3& a, const Vec3& b) { return a.z() < b.z(); });
  std::size_t elements = 0;
  for (auto _ : st) {
    const auto r = ball.at(x, top);
    elements = r.elements;
    benchmark::DoNotOptimize(r.strain);
  }
  st.counters["elements"] = static_cast<double>(elements);
  st.counters["ns_per_element"] = benchmark::Counter(static_cast<double>(elements) * static_cast<double>(st.iterations()),
                                                     benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Streaming read of `bytes` (a sum over doubles): the bandwidth a force loop can reach when its
// per-element data have that size.
void read_bandwidth(benchmark::State& st, std::size_t bytes) {
  std::vector<double> a(bytes / sizeof(double));
  std::iota(a.begin(), a.end(), 0.0);
  for (auto _ : st) {
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    for (std::size_t i = 0; i + 3 < a.size(); i += 4) {
      s0 += a[i];
      s1 += a[i + 1];
      s2 += a[i + 2];
      s3 += a[i + 3];
    }
    benchmark::DoNotOptimize(s0 + s1 + s2 + s3);
  }
  st.SetBytesProcessed(static_cast<std::int64_t>(st.iterations()) * static_cast<std::int64_t>(bytes));
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  for (const Level& level : levels()) {
    for (const std::string m : {"gps", "gps_energy", "gps_large_strain", "corotational", "linear"})
      benchmark::RegisterBenchmark(("Force/" + m + "/" + level.name).c_str(), force, m, &level)->Unit(benchmark::kMicrosecond);
    for (const std::string m : {"gps", "gps_energy", "gps_large_strain", "corotational", "linear", "gps_visco3", "scene", "scene_large_strain"})
      benchmark::RegisterBenchmark(("Step/" + m + "/" + level.name).c_str(), step, m, &level)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("TipStrain/" + level.name).c_str(), tip_strain, &level)->Unit(benchmark::kMicrosecond);
  }
  for (const auto& [name, bytes] : std::vector<std::pair<std::string, std::size_t>>{
           {"liver2_1.5k", 1493 * 280}, {"liver2_12k", 11944 * 280}, {"liver2_96k", 95552 * 280}, {"256MiB", 256u << 20}})
    benchmark::RegisterBenchmark(("ReadBandwidth/" + name).c_str(), read_bandwidth, bytes)->Unit(benchmark::kMicrosecond);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
