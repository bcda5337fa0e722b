// The material mechanisms as files and as energy maps: the viscoelastic fields of a material file  // SPDX-License-Identifier: Apache-2.0
// checked by name, Fung's stiffening reaching the model, QLV's energy maps against their
// definitions, and the rules between a model's parts.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/tissue/gps/fung_map.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/constant_q.hpp"
#include "viscera/tissue/viscoelastic/constant_q_fit.hpp"
#include "viscera/tissue/viscoelastic/figure2.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

#include "test_support.hpp"

using namespace viscera::tissue;
using namespace viscera::common;
namespace test = viscera::tissue::test;

TEST(MaterialFile, ViscoelasticFieldsAreCheckedByName) {
  const auto message = [](const std::string& json) {
    try {
      parse_material(json, "tissue.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = R"({"density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 3000, "poisson_ratio": 0.3}, )";
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": -1}})").find("tissue.json: viscoelasticity.shear_q"), std::string::npos);
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": 4.8, "band_hz": [10, 0.01]}})").find("viscoelasticity.band_hz"), std::string::npos);
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": 4.8, "mechanisms": 9}})").find("viscoelasticity.mechanisms"), std::string::npos);
  EXPECT_NE(message(R"({"density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": -3000, "poisson_ratio": 0.3}})")
                .find("youngs_modulus_pa"),
            std::string::npos);
  EXPECT_NE(message(R"({"density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 3000, "poisson_ratio": 0.5}})")
                .find("poisson_ratio"),
            std::string::npos);
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": 4.8, "qlv_form": "energetic"}})").find("tissue.json: viscoelasticity.qlv_form"),
            std::string::npos);
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": 4.8, "band": [0.01, 10]}})").find("tissue.json: viscoelasticity.band: unknown field"),
            std::string::npos);
  EXPECT_NE(message(head + R"("viscosity": {"shear_q": 4.8}})").find("tissue.json: viscosity: unknown field"), std::string::npos);
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": 4.8, "qlv_form": "energy", "compression_ratio": 0}})")
                .find("viscoelasticity.compression_ratio"),
            std::string::npos);
  EXPECT_NE(message(head + R"("viscoelasticity": {"shear_q": 4.8, "compression_ratio": 2}})")
                .find("viscoelasticity.compression_ratio: 2 needs \"qlv_form\": \"energy\""),
            std::string::npos);
  const Material m = parse_material(
      head + R"("viscoelasticity": {"shear_q": 4.8, "bulk_q": 20, "band_hz": [0.01, 10], "mechanisms": 3, "reference_frequency_hz": 2}})", "ok.json");
  ASSERT_TRUE(m.viscoelasticity.has_value());
  EXPECT_EQ(m.viscoelasticity->mechanisms, 3);
}

TEST(MaterialFile, FungStiffeningInItsEnergyFormReachesTheModelAsAConservativeResponse) {
  // "qlv_form": "energy" (and an asymmetry) from the file to the organ's GPS: stretched 15% along x
  // and 5% shortened along z, its tangent is symmetric (the forces are an energy's gradient); the
  // published edge map's is not (its edges stiffen by different factors).
  const std::string head = R"({"density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 3000, "poisson_ratio": 0.3}, )";
  std::mt19937_64 rng(5);
  const auto rest = test::random_tet(rng);
  std::vector<Vec3> x(rest.begin(), rest.end());
  for (auto& p : x) p = Vec3(1.15 * p.x(), p.y(), 0.95 * p.z());
  const auto asymmetry = [&](const std::string& form) {
    const Material m = parse_material(head + R"("viscoelasticity": {"shear_q": 4.8, "bulk_q": 4.8, "qlv_stiffening": 8)" + form + "}}", "fung.json");
    const ViscoelasticSetup ve = make_viscoelastic(m.elasticity, *m.viscoelasticity);
    const auto model = make_force_model("gps_energy", test::single_tet_mesh(rest), {ve.unrelaxed_elasticity}, 0.5, ve.gps);
    const Mat12 K = model->element_tangent(x, 0);
    return (K - K.transpose()).norm() / K.norm();
  };
  EXPECT_LT(asymmetry(R"(, "qlv_form": "energy", "compression_ratio": 2)"), 1e-12);
  EXPECT_LT(asymmetry(R"(, "qlv_form": "energy")"), 1e-12);
  EXPECT_GT(asymmetry(""), 1e-4);  // the default: the published edge map
  // The energy form relaxes the whole tension: a bulk that does not relax as the shear is refused.
  const Material elastic_bulk =
      parse_material(head + R"("viscoelasticity": {"shear_q": 4.8, "qlv_stiffening": 8, "qlv_form": "energy"}})", "fung.json");
  try {
    make_viscoelastic(elastic_bulk.elasticity, *elastic_bulk.viscoelasticity, "fung.json");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fung.json: qlv_form"), std::string::npos) << e.what();
  }
}

TEST(Qlv, UniformDilatationStiffensExactlyAsFungsExponential) {
  // Every edge of a tet under uniform dilatation has the same strain e; the QLV tension is the
  // linear one scaled by (exp(B e) - 1) / (B e), in both forms (the energy form's h h' is the
  // edge map g by construction).
  const std::array<Vec3, 4> rest{Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.004, 0.009, 0), Vec3(0.003, 0.002, 0.008)};
  const double B = 12.0;
  const GpsModel linear(test::single_tet_mesh(rest), {test::soft_tissue()});
  for (const auto form : {GpsStiffening::Form::edge_map, GpsStiffening::Form::energy}) {
    GpsOptions q;
    q.mechanisms.stiffening.b = B;
    q.mechanisms.stiffening.form = form;
    const GpsModel qlv(test::single_tet_mesh(rest), {test::soft_tissue()}, {}, q);
    for (double e : {-0.1, -0.0004, 0.0007, 0.05, 0.2}) {  // both sides of the series/closed-form switch at |B e| = 0.01
      std::vector<Vec3> x;
      x.reserve(rest.size());
      for (const auto& p : rest) x.push_back((1 + e) * p);
      std::vector<Vec3> fl(4, Vec3::Zero()), fq(4, Vec3::Zero());
      linear.add_forces(x, fl);
      qlv.add_forces(x, fq);
      const double factor = std::expm1(B * e) / (B * e);
      for (int i = 0; i < 4; ++i) EXPECT_LT((fq[i] - factor * fl[i]).norm(), 1e-10 * fl[i].norm()) << e;
    }
  }
}

TEST(Qlv, EnergyMapSatisfiesItsDefinition) {
  // h h' = (exp(B e) - 1) / B and h'' = d h' / de, checked against the closed form and central
  // differences on both sides of the series switch.
  for (const double B : {0.5, 8.0, 40.0})
    for (const double e : {-0.3, -0.01, -1e-4, 0.0, 2e-5, 1e-3, 0.05, 0.25}) {
      const FungEnergyMap m = fung_energy_map(B, e);
      EXPECT_NEAR(m.h * m.dh, std::expm1(B * e) / B, 1e-13 * (1 + std::abs(std::expm1(B * e) / B))) << B << " " << e;
      EXPECT_GT(m.dh, 0.0);
      const double d = 1e-6 / B;
      const double fd1 = (fung_energy_map(B, e + d).h - fung_energy_map(B, e - d).h) / (2 * d);
      const double fd2 = (fung_energy_map(B, e + d).dh - fung_energy_map(B, e - d).dh) / (2 * d);
      EXPECT_NEAR(m.dh, fd1, 1e-7 * m.dh) << B << " " << e;
      EXPECT_NEAR(m.d2h, fd2, 1e-5 * (B + std::abs(m.d2h))) << B << " " << e;
    }
  EXPECT_NEAR(fung_energy_map(9.0, 0.0).d2h, 3.0, 1e-12);  // h''(0) = B / 3
  // Asymmetry: compressed edges r times as stiff, tension unchanged, away from the smooth
  // transition of width w around 0; h' and h'' equal central differences everywhere.
  for (const double r : {0.3, 2.5})
    for (const double e : {-0.2, -0.1, 0.1, 0.2}) {
      const FungEnergyMap m = edge_energy_map(6.0, r, e);
      const double g = std::expm1(6.0 * e) / 6.0;
      EXPECT_NEAR(m.h * m.dh, e < 0 ? r * g : g, 1e-7 * std::abs(g)) << r << " " << e;
      EXPECT_NEAR(edge_energy_map(0.0, r, e).h * edge_energy_map(0.0, r, e).dh, e < 0 ? r * e : e, 1e-7) << r << " " << e;
    }
  for (const double e : {-0.02, -0.004, 0.0, 0.003, 0.02}) {
    const FungEnergyMap m = edge_energy_map(6.0, 0.3, e);
    const double d = 1e-7;
    EXPECT_NEAR(m.dh, (edge_energy_map(6.0, 0.3, e + d).h - edge_energy_map(6.0, 0.3, e - d).h) / (2 * d), 1e-6) << e;
    EXPECT_NEAR(m.d2h, (edge_energy_map(6.0, 0.3, e + d).dh - edge_energy_map(6.0, 0.3, e - d).dh) / (2 * d), 1e-4 * (1 + std::abs(m.d2h))) << e;
    EXPECT_GT(m.dh, 0.0);
  }
}

TEST(Qlv, TheForceLoopsBranchFreeEnergyMapIsTheSameFunction) {
  // lanes::exp against the library's exp over the clamped range, to 2 ulp.
  double worst_ulp = 0;
  for (double x = -700.0; x <= 700.0; x += 0.37) {
    const double want = std::exp(x), got = lanes::exp(x);
    worst_ulp = std::max(worst_ulp, std::abs(got - want) / (std::nextafter(want, INFINITY) - want));
  }
  for (double x = -1.0; x <= 1.0; x += 1e-3) {
    const double want = std::exp(x), got = lanes::exp(x);
    worst_ulp = std::max(worst_ulp, std::abs(got - want) / (std::nextafter(want, INFINITY) - want));
  }
  EXPECT_LE(worst_ulp, 2.0);
  EXPECT_TRUE(std::isfinite(lanes::exp(1e6)) && lanes::exp(-1e6) > 0);  // clamped, never inf or 0
  // h and h' of every shape, with and without asymmetry, against edge_energy_map (the series and
  // the closed form on its own switch, std::expm1) across both switches and large strains.
  for (const StiffeningShape shape : {StiffeningShape::exponential, StiffeningShape::odd_exponential, StiffeningShape::odd_polynomial})
    for (const double B : {0.0, 0.5, 8.0, 17.5, 40.0})
      for (const double r : {1.0, 0.3, 2.5})
        for (double e = -0.6; e <= 0.6; e += 0.00137) {
          if (B == 0.0 && r == 1.0) continue;  // no map: the force loop does not call it
          const FungEnergyMap want = edge_energy_map(B, r, e, shape);
          double h = 0, dh = 0;
          lanes::edge_energy_map(B, r, shape, e, h, dh);
          // 1e-12: edge_energy_map's own series stops at x^4 below |x| = 1e-2 (x^5 / 2520 left out).
          EXPECT_NEAR(h, want.h, 1e-12 * (std::abs(want.h) + 1e-3)) << B << " " << r << " " << e;
          EXPECT_NEAR(dh, want.dh, 1e-12 * std::abs(want.dh)) << B << " " << r << " " << e;
        }
}

TEST(Qlv, OddShapesEnergyMapsSatisfyTheirDefinitions) {
  // The odd shapes against their closed-form laws g: h h' = g, h odd, h' > 0, and h', h'' equal
  // central differences (away from 0 for the odd exponential, whose h'' jumps there).
  const auto g_odd_exp = [](double B, double e) { return std::copysign(std::expm1(B * std::abs(e)) / B, e); };
  const auto g_poly = [](double B, double e) { return e * (1 + B * B * e * e / 6); };
  for (const auto shape : {StiffeningShape::odd_exponential, StiffeningShape::odd_polynomial})
    for (const double B : {0.5, 8.0, 30.0})
      for (const double e : {-0.2, -0.05, -1e-3, 1e-3, 0.05, 0.2}) {
        const FungEnergyMap m = stiffening_energy_map(shape, B, e);
        const double g = shape == StiffeningShape::odd_exponential ? g_odd_exp(B, e) : g_poly(B, e);
        EXPECT_NEAR(m.h * m.dh, g, 1e-12 * (1 + std::abs(g))) << B << " " << e;
        EXPECT_NEAR(stiffening_energy_map(shape, B, -e).h, -m.h, 1e-15 * (1 + std::abs(m.h)));
        EXPECT_GT(m.dh, 0.0);
        const double d = 1e-6 / B * std::min(1.0, std::abs(e) * B);
        EXPECT_NEAR(m.dh, (stiffening_energy_map(shape, B, e + d).h - stiffening_energy_map(shape, B, e - d).h) / (2 * d), 1e-6 * m.dh)
            << B << " " << e;
        EXPECT_NEAR(m.d2h, (stiffening_energy_map(shape, B, e + d).dh - stiffening_energy_map(shape, B, e - d).dh) / (2 * d),
                    1e-4 * (B + std::abs(m.d2h)))
            << B << " " << e;
      }
  // Odd shapes exist in the energy form only.
  GpsMechanisms mech;
  mech.stiffening.b = 5.0;
  mech.stiffening.shape = StiffeningShape::odd_polynomial;
  EXPECT_THROW(mech.validate(), std::invalid_argument);
  mech.stiffening.form = GpsStiffening::Form::energy;
  EXPECT_NO_THROW(mech.validate());
}

// Each part of the composition refuses what it cannot run, naming itself; the rules between parts
// are checked where the parts meet; a valid composition reaches the model unchanged.
TEST(GpsMechanisms, EachPartAndEachRuleBetweenPartsRefusesWhatItCannotRun) {
  const auto refusal = [](const GpsMechanisms& m) {
    try {
      m.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  GpsMechanisms ok;
  ok.viscous = {{1.0, 10.0}, {0.2, 0.1}, {}, 0.01};
  ok.stiffening = {8.0, GpsStiffening::Form::energy};
  ok.asymmetry.compression_ratio = 2.0;
  ok.softening.d = 0.3;
  EXPECT_EQ(refusal(ok), "");
  EXPECT_TRUE(ok.energy_map());
  EXPECT_TRUE(ok.has_memory());
  EXPECT_FALSE(GpsMechanisms{}.has_memory());

  GpsMechanisms m = ok;
  m.viscous.shear_weight.pop_back();
  EXPECT_NE(refusal(m).find("viscous part"), std::string::npos);
  m = ok;
  m.viscous.omega_rad_s.assign(9, 1.0);
  m.viscous.shear_weight.assign(9, 0.01);
  EXPECT_NE(refusal(m).find("at most 8"), std::string::npos);
  m = ok;
  m.viscous.omega_rad_s[0] = 0.0;
  EXPECT_NE(refusal(m).find("viscous part"), std::string::npos);
  m = ok;
  m.viscous.kelvin_voigt_time_s = -1e-3;
  EXPECT_NE(refusal(m).find("Kelvin-Voigt"), std::string::npos);
  m = ok;
  m.stiffening.b = std::nan("");
  EXPECT_NE(refusal(m).find("stiffening"), std::string::npos);
  m = ok;
  m.asymmetry.compression_ratio = 0.0;
  EXPECT_NE(refusal(m).find("asymmetry"), std::string::npos);
  m = ok;
  m.softening.d = 1.0;
  EXPECT_NE(refusal(m).find("softening"), std::string::npos);
  // Between parts: asymmetry lives in the energy form only ...
  m = ok;
  m.stiffening.form = GpsStiffening::Form::edge_map;
  EXPECT_NE(refusal(m).find("energy form"), std::string::npos);
  // ... and the energy form relaxes the whole tension, so bulk and shear must relax alike.
  m = ok;
  m.viscous.bulk_weight = {0.0, 0.0};
  EXPECT_NE(refusal(m).find("bulk and shear"), std::string::npos);
  m.stiffening.b = 0.0;
  m.asymmetry.compression_ratio = 1.0;  // no energy map left: the bulk may relax on its own
  EXPECT_EQ(refusal(m), "");

  const auto mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 1, 1, 1));
  const Mat6 D = elasticity_matrix(IsotropicElasticity{3e3, 0.3});
  GpsOptions bad_options;
  bad_options.mechanisms.softening.d = 1.5;
  EXPECT_THROW(GpsModel(mesh, {D}, {}, bad_options), std::invalid_argument);
  EXPECT_THROW(GpsModel(mesh, {D}, std::vector<std::uint16_t>(mesh->tet_count(), 1)), std::invalid_argument);
  GpsOptions options;
  options.variant = GpsVariant::energy_consistent;
  options.mechanisms = ok;
  const GpsModel model(mesh, {D}, {}, options);
  EXPECT_EQ(model.options().mechanisms.viscous.omega_rad_s, ok.viscous.omega_rad_s);
  EXPECT_EQ(model.stiffness_damping_time_s(), 0.01);
  // Memory per block: elongations, 2 mechanisms, 2 softening extremes (6 x 8 doubles each).
  EXPECT_EQ(model.memory_size(), (mesh->tet_count() + 7) / 8 * (1 + 2 + 2) * 6 * 8);
}
