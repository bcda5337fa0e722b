// Forces on several threads against the one-thread evaluation (an independent path through the  // SPDX-License-Identifier: Apache-2.0
// same model): equal to rounding, memory variables advanced the same, deterministic bit for bit
// whatever the threads' timing, instability (NaN) still reported, and models that do not split
// (corotational FE) still whole. An explicit run on two threads follows the one-thread run.
#include "viscera/runtime/parallel_forces.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <random>

#include <gtest/gtest.h>

#include "viscera/tissue/cutting/mesh_cutter.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/mesh/locality_order.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

using namespace viscera::runtime;
using namespace viscera::tissue;

namespace {

struct Liver {
  std::shared_ptr<TetMesh> mesh;
  Mat6 D = elasticity_matrix(IsotropicElasticity{5e3, 0.45});
  Liver() {
    mesh = std::make_shared<TetMesh>(read_tet_mesh(std::string(VISCERA_DATA_DIR) + "/meshes/liver2.msh"));
    scale_mesh(*mesh, 0.08);
  }
  // A deformed, rotated configuration, so every edge carries tension.
  std::vector<Vec3> deformed() const {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n;
    const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    std::vector<Vec3> x = mesh->nodes;
    for (auto& p : x) p = R * Vec3(1.04 * p.x(), p.y(), p.z()) + 1e-4 * Vec3(n(rng), n(rng), n(rng));
    return x;
  }
};

double max_relative_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0, scale = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    d = std::max(d, (a[i] - b[i]).norm());
    scale = std::max(scale, b[i].norm());
  }
  return d / scale;
}

}  // namespace

TEST(ParallelForces, EqualTheOneThreadForcesAndMemoryAndAreDeterministic) {
  const Liver liver;
  const ViscoelasticSetup ve = make_viscoelastic(liver.D, ViscoelasticSpec{});
  const auto model = make_force_model("gps_energy", liver.mesh, {ve.unrelaxed_elasticity}, 0.5, ve.gps);
  const auto x = liver.deformed();
  const std::size_t nm = model->memory_size();
  ASSERT_GT(nm, 0u);
  std::vector<double> mem_serial(nm, 0.0), mem_parallel(nm, 0.0);
  std::vector<Vec3> f_serial(x.size(), Vec3(0, 0, -0.01)), f_parallel = f_serial;  // forces are added to what is there
  model->add_forces(x, f_serial, {mem_serial, mem_serial, 1e-3});
  ParallelForces parallel(*model, 2, 4);
  parallel(x, f_parallel, {mem_parallel, mem_parallel, 1e-3});
  EXPECT_LT(max_relative_difference(f_parallel, f_serial), 1e-13);
  double mem_diff = 0;
  for (std::size_t k = 0; k < nm; ++k) mem_diff = std::max(mem_diff, std::abs(mem_parallel[k] - mem_serial[k]));
  EXPECT_EQ(mem_diff, 0.0);  // each element's memory is computed by exactly one thread, the same way
  // Repeated evaluations (helpers taking different chunks each time): the same bits.
  for (int rep = 0; rep < 50; ++rep) {
    std::vector<double> mem(nm, 0.0);
    std::vector<Vec3> f(x.size(), Vec3(0, 0, -0.01));
    parallel(x, f, {mem, mem, 1e-3});
    for (std::size_t i = 0; i < f.size(); ++i) ASSERT_EQ(f[i], f_parallel[i]) << "repetition " << rep << ", node " << i;
  }
  // The same chunks on one thread: the same bits as on two (what lets a session be re-simulated
  // bit for bit whatever the thread count).
  ParallelForces one_thread(*model, 1, 4);
  std::vector<double> mem_one(nm, 0.0);
  std::vector<Vec3> f_one(x.size(), Vec3(0, 0, -0.01));
  one_thread(x, f_one, {mem_one, mem_one, 1e-3});
  for (std::size_t i = 0; i < f_one.size(); ++i) ASSERT_EQ(f_one[i], f_parallel[i]) << "node " << i;
}

TEST(ParallelForces, ReportInstabilityAndKeepModelsThatDoNotSplitWhole) {
  const Liver liver;
  const auto gps = make_force_model("gps", liver.mesh, {liver.D});
  auto x = liver.deformed();
  ParallelForces parallel(*gps, 2, 4);
  std::vector<Vec3> f(x.size(), Vec3::Zero()), ref(x.size(), Vec3::Zero());
  const double strain = parallel(x, f, {}).max_edge_strain;
  EXPECT_NEAR(strain, gps->add_forces(x, ref).max_edge_strain, 1e-15);
  x[liver.mesh->tets.back()[2]] = Vec3(std::nan(""), 0, 0);  // an element of the last chunk
  std::fill(f.begin(), f.end(), Vec3::Zero());
  EXPECT_TRUE(std::isnan(parallel(x, f, {}).max_edge_strain));

  const auto corotational = make_force_model("corotational", liver.mesh, {liver.D});
  const auto y = liver.deformed();
  ParallelForces whole(*corotational, 2, 4);
  std::vector<Vec3> a(y.size(), Vec3::Zero()), b(y.size(), Vec3::Zero());
  whole(y, a, {});
  corotational->add_forces(y, b);
  EXPECT_LT(max_relative_difference(a, b), 1e-14);
}

TEST(ParallelForces, AnExplicitRunOnTwoThreadsFollowsTheOneThreadRun) {
  const Liver liver;
  const ViscoelasticSetup ve = make_viscoelastic(liver.D, ViscoelasticSpec{});
  const auto model = make_force_model("gps_energy", liver.mesh, {ve.unrelaxed_elasticity}, 0.5, ve.gps);
  BoundaryConditions bc;
  Box slab = bounding_box(*liver.mesh);
  slab.hi.z() = slab.lo.z() + 0.2 * (slab.hi.z() - slab.lo.z());
  bc.fixed_nodes = surface_nodes_in_box(*liver.mesh, slab);
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  const std::vector<double> rho(liver.mesh->tet_count(), 1060.0);
  ExplicitIntegrator one(*model, rho, bc), two(*model, rho, bc);
  ParallelForces parallel(*model, 2, 4);
  two.set_force_evaluation([&](std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& m) { return parallel(x, f, m); });
  State a = State::at_rest(*liver.mesh), b = a;
  one.advance(a, 0.05);
  two.advance(b, 0.05);
  double sag = 0;
  for (std::size_t i = 0; i < a.x.size(); ++i) sag = std::max(sag, (a.x[i] - liver.mesh->nodes[i]).norm());
  double d = 0;
  for (std::size_t i = 0; i < a.x.size(); ++i) d = std::max(d, (a.x[i] - b.x[i]).norm());
  EXPECT_GT(sag, 1e-3);
  EXPECT_LT(d, 1e-10 * sag);
}

// The integrator's node update split over the threads (an organ of more than kParallelNodesFrom
// nodes), each range adding the chunks' buffers over its own nodes first (as the server runs it),
// gives the same bits as one thread with the same chunks: each node's update reads that node alone
// and its sum takes the chunks in one order. Against the buffers summed before the node loop (the
// force field added after them instead of before): equal without the field, to rounding with it.
// With a contact-like field on some nodes (their implicit springs and dashpots) and without.
TEST(ParallelForces, TheNodeUpdateSplitOverThreadsGivesTheSameBits) {
  const auto mesh = std::make_shared<TetMesh>(ordered_for_locality(make_box_mesh(Vec3(0, 0, 0), Vec3(0.12, 0.05, 0.04), 36, 16, 14)));
  ASSERT_GE(mesh->node_count(), kParallelNodesFrom);
  const Mat6 D = elasticity_matrix(IsotropicElasticity{5e3, 0.45});
  const ViscoelasticSetup ve = make_viscoelastic(D, ViscoelasticSpec{});
  const auto model = make_force_model("gps_energy", mesh, {ve.unrelaxed_elasticity}, 0.5, ve.gps);
  BoundaryConditions bc;
  Box slab = bounding_box(*mesh);
  slab.hi.z() = slab.lo.z() + 0.1 * (slab.hi.z() - slab.lo.z());
  bc.fixed_nodes = surface_nodes_in_box(*mesh, slab);
  bc.gravity_m_s2 = Vec3(0, 0, -9.81);
  for (const bool field : {false, true}) {
    if (field)  // springs towards the rest shape on every 7th node, a dashpot on every 5th
      bc.force_field = [&](const BoundaryConditions::FieldEvaluation& e) {
        for (std::size_t i = 0; i < e.x.size(); i += 7) {
          e.f[i] += 50.0 * (mesh->nodes[i] - e.x[i]);
          e.stiffness[i] += 50.0;
        }
        for (std::size_t i = 0; i < e.x.size(); i += 5) e.damping[i] += 0.2;
      };
    const std::vector<double> rho(mesh->tet_count(), 1060.0);
    ExplicitIntegrator whole(*model, rho, bc), split(*model, rho, bc), summed_first(*model, rho, bc);
    ParallelForces one(*model, 1, 3), parallel(*model, 3, 3);
    whole.set_force_evaluation([&](std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& m) { return one.evaluate_leaving_sums(x, f, m); });
    whole.set_node_loop([&](std::size_t n, const std::function<void(std::size_t, std::size_t)>& update) { one.for_ranges(n, update); });
    split.set_force_evaluation(
        [&](std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& m) { return parallel.evaluate_leaving_sums(x, f, m); });
    summed_first.set_force_evaluation([&](std::span<const Vec3> x, std::span<Vec3> f, const MemoryUpdate& m) { return parallel(x, f, m); });
    std::vector<std::pair<std::size_t, std::size_t>> ranges;
    split.set_node_loop([&](std::size_t n, const std::function<void(std::size_t, std::size_t)>& update) {
      std::mutex m;
      parallel.for_ranges(n, [&](std::size_t first, std::size_t last) {
        {
          const std::lock_guard lock(m);
          ranges.emplace_back(first, last);
        }
        update(first, last);
      });
    });
    State a = State::at_rest(*mesh), b = a, c = a;
    const long steps = whole.advance(a, 0.01);
    ASSERT_EQ(split.advance(b, 0.01), steps);
    ASSERT_EQ(summed_first.advance(c, 0.01), steps);
    double sag = 0;
    for (std::size_t i = 0; i < a.x.size(); ++i) sag = std::max(sag, (a.x[i] - mesh->nodes[i]).norm());
    EXPECT_GT(sag, 1e-5) << "the bar sags";
    EXPECT_EQ(a.x, b.x) << (field ? "with the field" : "without");
    EXPECT_EQ(a.v, b.v) << (field ? "with the field" : "without");
    EXPECT_EQ(a.memory, b.memory);
    double d = 0;
    for (std::size_t i = 0; i < a.x.size(); ++i) d = std::max(d, (a.x[i] - c.x[i]).norm());
    if (field)
      EXPECT_LT(d, 1e-10 * sag);
    else
      EXPECT_EQ(d, 0.0) << "the buffers summed in the node loop or before it: the same sums";
    // Every sub-step split [0, n) into three ranges that cover it.
    ASSERT_EQ(ranges.size(), 3 * static_cast<std::size_t>(steps));
    std::sort(ranges.begin(), ranges.end());
    for (std::size_t k = 0; k < ranges.size(); k += static_cast<std::size_t>(steps)) EXPECT_LT(ranges[k].first, ranges[k].second);
    EXPECT_EQ(ranges.front().first, 0u);
    EXPECT_EQ(ranges.back().second, mesh->node_count());
  }
}

// Each chunk's buffer is cleared and added only over the nodes its elements name. A cut changes
// elements in place and adds elements and nodes: told of it (follow_model), the chunks' forces
// still add up to the model's forces in one piece; and an ordered mesh gives the same forces as
// the mesh it renumbers.
TEST(ParallelForces, FollowACutOfTheModelAndTheLocalityOrder) {
  const auto mesh = std::make_shared<TetMesh>(ordered_for_locality(make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2)));
  const Mat6 D = elasticity_matrix(IsotropicElasticity{5e3, 0.45});
  const ViscoelasticSetup ve = make_viscoelastic(D, ViscoelasticSpec{});
  GpsOptions o;
  o.variant = GpsVariant::energy_consistent;
  o.volume_stiffness_fraction = 0.5;
  o.mechanisms = ve.gps;
  GpsModel gps(mesh, {ve.unrelaxed_elasticity}, {}, o);
  ParallelForces parallel(gps, 2, 4);
  const auto deformed = [](const std::vector<Vec3>& rest) {
    std::vector<Vec3> x = rest;
    for (auto& p : x) p = Vec3(1.03 * p.x(), p.y() + 0.2 * p.x() * p.x(), p.z());
    return x;
  };
  const auto compare = [&](const char* when) {
    const auto x = deformed(mesh->nodes);
    std::vector<double> m1(gps.memory_size(), 0.0), m2 = m1;
    std::vector<Vec3> one(x.size(), Vec3::Zero()), two = one;
    gps.add_forces(x, one, {m1, m1, 1e-3});
    parallel(x, two, {m2, m2, 1e-3});
    EXPECT_LT(max_relative_difference(two, one), 1e-13) << when;
    EXPECT_EQ(m1, m2) << when;
  };
  compare("before the cut");
  // The order changes nothing but the numbering: the renumbered mesh's forces, mapped back.
  {
    Renumbering r;
    const auto raw = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.10, 0.02, 0.02), 10, 2, 2));
    const TetMesh again = ordered_for_locality(*raw, &r);
    ASSERT_EQ(again.tets, mesh->tets);
    const GpsModel unordered(raw, {ve.unrelaxed_elasticity}, {}, o);
    const auto xr = deformed(raw->nodes), xo = deformed(mesh->nodes);
    std::vector<Vec3> fr(xr.size(), Vec3::Zero()), fo(xo.size(), Vec3::Zero());
    unordered.add_forces(xr, fr);
    gps.add_forces(xo, fo);
    std::vector<Vec3> back(fo.size());
    for (std::size_t v = 0; v < fo.size(); ++v) back[static_cast<std::size_t>(r.old_node[v])] = fo[v];
    EXPECT_LT(max_relative_difference(back, fr), 1e-13);
  }
  // Two blades into the bar, each followed.
  MeshCutter cutter(*mesh);
  std::vector<double> memory(gps.memory_size(), 0.0);
  for (const double xc : {0.034, 0.071}) {
    for (int i = 0; i < 6; ++i) {
      const double za = 0.03 - 0.004 * i, zb = za - 0.004;
      const std::vector<Vec3> x = mesh->nodes;
      const CutChange c = cutter.cut({Vec3(xc, -0.01, za), Vec3(xc, 0.03, za), Vec3(xc, -0.01, zb), Vec3(xc, 0.03, zb)}, x, 0);
      gps.follow_edit(c.edit(), memory);
      parallel.follow_model();
    }
    compare(xc < 0.05 ? "after the first cut" : "after the second cut");
  }
  EXPECT_GT(mesh->tet_count(), 240u);  // the blades cut
}
