// Materials a press cannot break (server/runtime/stiffening_limit.hpp): the stiffest material of  // SPDX-License-Identifier: Apache-2.0
// each stiffening form and shape that the server accepts is pressed 3 cm into the 1.5k liver by
// the 6 mm probe at 2 cm/s and held, as the server steps it (the scene's organ, its probe contact,
// 1 ms ticks; no DDS): no step may call the organ unstable (the server would reset it under the
// hand), and the next stiffer material is refused when the organ is built. Release only (label
// "physics"): seconds of a stiffened organ at up to 64 sub-steps a step.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>

#include <gtest/gtest.h>

#include "viscera/common/input_error.hpp"
#include "viscera/runtime/organ.hpp"
#include "viscera/runtime/scene_file.hpp"
#include "viscera/runtime/stiffening_limit.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

#include "organ_press.hpp"

using namespace viscera::runtime;
using namespace viscera::tissue;
using viscera::runtime::test::Press;
using viscera::runtime::test::press;

namespace {

const std::string kScene = std::string(VISCERA_DATA_DIR) + "/scenes/liver.json";

/// The liver scene with a material of the liver's elasticity and constant Q and this stiffening.
SceneSpec scene_with(const std::string& stiffening_json, const std::string& name) {
  const std::string path = std::string(VISCERA_TEST_TMP) + "/" + name + ".json";
  std::filesystem::create_directories(VISCERA_TEST_TMP);
  std::ofstream(path) << R"({"name": ")" << name
                      << R"(", "density_kg_m3": 1060, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 5000, "poisson_ratio": 0.45},
  "viscoelasticity": {"model": "constant_q", "shear_q": 4.8, "bulk_q": 4.8, "band_hz": [0.01, 10], "mechanisms": 3,
  "reference_frequency_hz": 2, )"
                      << stiffening_json << "}}";
  SceneSpec spec = read_scene_file(kScene);
  spec.material = path;
  return spec;
}

struct Form {
  const char* name;
  const char* json;  ///< the form and shape, before "qlv_stiffening"
};

/// Its name in test names (gtest prints a parameter's bytes otherwise).
void PrintTo(const Form& f, std::ostream* os) { *os << f.name; }

class StiffestAccepted : public ::testing::TestWithParam<Form> {};

TEST_P(StiffestAccepted, HoldsAThreeCentimetrePressAndTheNextIsRefused) {
  const Form form = GetParam();
  // The largest B the server takes for this form and shape on this scene: the rule's own search,
  // at the integrator's cap (the budget of a machine aside), checked against the build below.
  SceneSpec probe_spec = scene_with(std::string(form.json) + R"("qlv_stiffening": 1)", std::string(form.name) + "-probe");
  const Material m = read_material_file(probe_spec.material);
  const GpsMechanisms mech = make_viscoelastic(m.elasticity, *m.viscoelasticity, probe_spec.material).gps;
  const double largest = largest_stiffening(mech, probe_spec.largest_edge_strain, ExplicitIntegrator::kMaxStiffenedSubSteps);
  ASSERT_GT(largest, 1.0) << form.name;
  char b[64];
  std::snprintf(b, sizeof b, "\"qlv_stiffening\": %.6g", 0.995 * largest);
  const SceneSpec accepted = scene_with(std::string(form.json) + b, std::string(form.name) + "-accepted");
  std::snprintf(b, sizeof b, "\"qlv_stiffening\": %.6g", 1.01 * largest);
  const SceneSpec refused = scene_with(std::string(form.json) + b, std::string(form.name) + "-refused");
  try {
    build_organ(refused, TickBudget{1e9});
    ADD_FAILURE() << form.name << ": B = " << 1.01 * largest << " was accepted";
  } catch (const viscera::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("viscoelasticity.qlv_stiffening"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(refused.material), std::string::npos) << e.what();
  }
  const Press r = press(accepted, 0.03);  // throws SimulationError where the server would reset
  std::printf("[ figure ] %s, B = %.3g (largest accepted %.4g): pressed %.1f mm, peak %.2f N, edge strain %.3f, up to %ld sub-steps a tick\n",
              form.name, 0.995 * largest, largest, 1e3 * r.depth_m, r.peak_force_n, r.peak_edge_strain, r.most_substeps);
  EXPECT_NEAR(r.depth_m, 0.03, 1e-6);
  EXPECT_LT(r.peak_edge_strain, accepted.largest_edge_strain) << "the press went past the strain the rule assumes";
}

INSTANTIATE_TEST_SUITE_P(Forms, StiffestAccepted,
                         ::testing::Values(Form{"edge_map", R"("qlv_form": "edge_map", )"}, Form{"energy_exponential", R"("qlv_form": "energy", )"},
                                           Form{"energy_odd_exponential", R"("qlv_form": "energy", "qlv_shape": "odd_exponential", )"},
                                           Form{"energy_odd_polynomial", R"("qlv_form": "energy", "qlv_shape": "odd_polynomial", )"}),
                         [](const ::testing::TestParamInfo<Form>& param) { return std::string(param.param.name); });

TEST(StiffMaterialPress, TheLabsTitinFitHoldsAThreeCentimetrePress) {
  SceneSpec spec = read_scene_file(kScene);
  spec.material = std::string(VISCERA_DATA_DIR) + "/materials/titin-fitted.json";
  const Press r = press(spec, 0.03);
  std::printf("[ figure ] titin-fitted.json: pressed %.1f mm, peak %.2f N, edge strain %.3f, up to %ld sub-steps a tick\n", 1e3 * r.depth_m,
              r.peak_force_n, r.peak_edge_strain, r.most_substeps);
  EXPECT_NEAR(r.depth_m, 0.03, 1e-6);
}

}  // namespace
