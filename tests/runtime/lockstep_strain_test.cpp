// The tissue's strain that every force carries, from a lockstep server in this process: the organ's  // SPDX-License-Identifier: Apache-2.0
// largest edge strain of the force's tick, and the strain at the instrument (Force.tip_strain),
// which stays as the mesh is refined where the largest edge strain grows.
#include <cmath>
#include <iostream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "lockstep_run.hpp"

namespace viscera::runtime {
namespace {

using namespace testing;

TEST(Lockstep, EveryForceCarriesTheOrgansLargestEdgeStrainOfItsTick) {
  const LockstepRun a = run(1);
  ASSERT_EQ(a.results.size(), static_cast<std::size_t>(kTicks + 1));
  std::string why;
  std::map<std::uint64_t, double> stepped;  // tick -> strain of the force stepped there
  double before_contact = 0, deepest = 0;
  std::vector<double> in_contact;  // the stepped forces' strain while pressing, in order
  for (const auto& r : a.results)
    for (const auto& payload : r.forces) {
      const auto f = proto::decode_force(payload, &why);
      ASSERT_TRUE(f) << why;
      if (f->step_time_ns == 0) {
        // Answered on the state after tick T (in step T + 1): the strain of tick T's evaluations.
        if (stepped.count(f->tick)) {
          EXPECT_EQ(f->max_edge_strain, stepped[f->tick]) << "tick " << f->tick;
        }
        continue;
      }
      stepped[f->tick] = f->max_edge_strain;
      if (!f->in_contact && deepest == 0) before_contact = std::max(before_contact, f->max_edge_strain);
      if (f->in_contact) {
        in_contact.push_back(f->max_edge_strain);
        deepest = std::max(deepest, f->max_edge_strain);
      }
    }
  // At rest the edges have their rest lengths; pressed 18 mm in, the tissue under a 6 mm tip is
  // strained by a few percent to a few tens, never near the 2 at which the integration stops.
  EXPECT_LT(before_contact, 1e-12);
  EXPECT_GT(deepest, 0.01);
  EXPECT_LT(deepest, 1.0);
  // The press goes steadily deeper: the strain grows with it. Not tick by tick (the surface rings,
  // and the largest edge strain follows it), but the last fifth of the press is well above the first.
  ASSERT_GT(in_contact.size(), 100u);
  const std::size_t fifth = in_contact.size() / 5;
  double first = 0, last = 0;
  for (std::size_t k = 0; k < fifth; ++k) {
    first += in_contact[k] / static_cast<double>(fifth);
    last += in_contact[in_contact.size() - 1 - k] / static_cast<double>(fifth);
  }
  EXPECT_GT(last, 2 * first) << "first fifth of the press " << first << ", last " << last;
}

/// The stepped forces of a run's press: tick -> (max_edge_strain, tip_strain, in contact), and the
/// answered-at-once forces' tip strains by the tick whose state answered them.
struct PressStrains {
  std::map<std::uint64_t, std::tuple<double, double, bool>> stepped;
  std::map<std::uint64_t, double> answered;
};
PressStrains press_strains(const LockstepRun& r) {
  PressStrains out;
  std::string why;
  for (const auto& result : r.results)
    for (const auto& payload : result.forces) {
      const auto f = proto::decode_force(payload, &why);
      EXPECT_TRUE(f) << why;
      if (!f) continue;
      if (f->step_time_ns > 0)
        out.stepped[f->tick] = {f->max_edge_strain, f->tip_strain, f->in_contact};
      else if (f->in_contact)
        out.answered[f->tick] = f->tip_strain;
    }
  return out;
}

TEST(Lockstep, TheStrainAtTheInstrumentStaysAsTheMeshIsRefinedWhereTheLargestEdgeStrainGrows) {
  // The same press (18 mm into the top of the liver, 6 mm tip), on the liver's mesh and on the
  // same mesh refined once (eight times the tetrahedra, half the edge length).
  // The scene's strain radius, 2 cm: 1.5 edges of the coarse mesh (over 1 cm, which the coarse mesh
  // cannot resolve, the two differed by 32%).
  const PressStrains coarse = press_strains(run(1));
  const PressStrains fine = press_strains(run(2, 0, {}, [](SceneSpec& s) { s.refine = 1; }));
  for (const PressStrains* p : {&coarse, &fine}) {
    bool touched = false;
    for (const auto& [tick, v] : p->stepped) {
      const auto [edge, tip, contact] = v;
      if (!contact) {
        EXPECT_EQ(tip, 0.0) << "tick " << tick << ": out of contact";
        continue;
      }
      touched = true;
      EXPECT_GT(tip, 0.0) << "tick " << tick;
      EXPECT_LT(tip, 1.0) << "tick " << tick;
    }
    EXPECT_TRUE(touched);
    // A force answered at once on the state after tick T carries tick T's strain at the instrument.
    for (const auto& [tick, tip] : p->answered) {
      if (const auto s = p->stepped.find(tick); s != p->stepped.end() && std::get<2>(s->second)) {
        EXPECT_EQ(tip, std::get<1>(s->second)) << "tick " << tick;
      }
    }
  }
  // The deepest press: the last tick in contact on both meshes.
  std::uint64_t last = 0;
  for (const auto& [tick, v] : coarse.stepped)
    if (std::get<2>(v) && fine.stepped.count(tick) && std::get<2>(fine.stepped.at(tick))) last = tick;
  ASSERT_GT(last, 0u);
  const auto [edge_coarse, tip_coarse, c1] = coarse.stepped.at(last);
  const auto [edge_fine, tip_fine, c2] = fine.stepped.at(last);
  const double edge_ratio = edge_fine / edge_coarse, tip_ratio = tip_fine / tip_coarse;
  std::cout << "[ figure ] tick +" << last - kFirstTick << ": largest edge strain " << edge_coarse << " (coarse) and " << edge_fine
            << " (refined), ratio " << edge_ratio << "; strain at the instrument " << tip_coarse << " and " << tip_fine << ", ratio " << tip_ratio
            << "\n";
  EXPECT_GT(edge_ratio, 1.3);  // the edge strain resolves the peak under the tip as the mesh is refined
  EXPECT_LT(std::abs(tip_ratio - 1.0), 0.15);  // the averaged strain stays within 15%
  EXPECT_LT(std::abs(tip_ratio - 1.0), 0.5 * (edge_ratio - 1.0));
}

}  // namespace
}  // namespace viscera::runtime
