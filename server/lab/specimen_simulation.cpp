#include "viscera/lab/specimen_simulation.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "viscera/common/input_error.hpp"
#include "viscera/lab/command_path.hpp"
#include "viscera/lab/golden_section.hpp"
#include "viscera/lab/noise_check.hpp"
#include "viscera/lab/stress_controlled.hpp"
#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"

namespace viscera::lab {

using namespace viscera::tissue;

Mat6 specimen_elasticity(double modulus_pa, bool shear) {
  const double nu = kSpecimenPoissonRatio;
  return elasticity_matrix(IsotropicElasticity{shear ? 2 * modulus_pa * (1 + nu) : modulus_pa, nu});
}

bool specimen_supports(const MaterialModel& m, Mode mode, std::string* why) {
  if (m.has(Mechanism::strain_stiffening) && m.stiffening_form == StiffeningForm::ogden) {
    *why = "the GPS's energy form has the exponential and odd laws (gps/fung_map.hpp), not Ogden's: not simulated on the specimen";
    return false;
  }
  const bool shaped = m.has(Mechanism::strain_stiffening) || m.has(Mechanism::tension_compression_asymmetry);
  const bool even_part =
      m.has(Mechanism::tension_compression_asymmetry) || (m.has(Mechanism::strain_stiffening) && m.stiffening_form == StiffeningForm::exponential);
  if (even_part && mode == Mode::simple_shear) {
    *why =
        "the law's elastic shape differs between positive and negative shear (exp(B gamma), or a compression ratio); an "
        "isotropic solid's shear stress is odd in the shear strain (mirror symmetry), so the GPS cannot represent it: "
        "not simulated on the specimen";
    return false;
  }
  *why = shaped ? "the elastic shape (stiffening, tension/compression asymmetry) in the GPS's energy form, its constants "
                  "calibrated to the law's curve over the data's strain range"
                : "";
  return true;
}

namespace {

StiffeningShape gps_shape(StiffeningForm f) {
  switch (f) {
    case StiffeningForm::exponential: return StiffeningShape::exponential;
    case StiffeningForm::odd_exponential: return StiffeningShape::odd_exponential;
    case StiffeningForm::odd_polynomial: return StiffeningShape::odd_polynomial;
    case StiffeningForm::ogden: break;  // not on the specimen (specimen_supports)
  }
  return StiffeningShape::exponential;
}

/// The specimen meshed with tetrahedra and the grips of its mode (x: pulling / shearing
/// direction; z: thickness); `moving` are the nodes the loading acts on.
struct Rig {
  std::shared_ptr<TetMesh> mesh;
  BoundaryConditions bc;
  std::vector<std::int32_t> moving;
  bool shear = false;
  double gauge = 0, area = 0;
};

Rig make_rig(Mode mode, const Specimen& sp) {
  Rig rig;
  rig.shear = mode == Mode::simple_shear;
  rig.mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(sp.length_m, sp.width_m, sp.thickness_m), 2, 1, 1));
  const double eps = 1e-9 * sp.length_m;
  for (std::size_t i = 0; i < rig.mesh->node_count(); ++i) {
    const Vec3& X = rig.mesh->nodes[i];
    const auto n = static_cast<std::int32_t>(i);
    auto& bc = rig.bc;
    if (!rig.shear) {
      if (X.x() < eps) {
        bc.fixed_axes.push_back({n, 0});
        if (X.y() < eps && X.z() < eps)
          bc.fixed_axes.push_back({n, 1}), bc.fixed_axes.push_back({n, 2});
        else if (X.z() < eps)
          bc.fixed_axes.push_back({n, 2});  // on the y axis: no rotation about x, z
        else if (X.y() < eps)
          bc.fixed_axes.push_back({n, 1});  // on the z axis: no rotation about y
      }
      if (X.x() > sp.length_m - eps) rig.moving.push_back(n);
    } else {
      if (X.z() < eps) {
        bc.fixed_nodes.push_back(n);
        continue;
      }
      bc.fixed_axes.push_back({n, 1});
      bc.fixed_axes.push_back({n, 2});
      if (X.z() > sp.thickness_m - eps) rig.moving.push_back(n);
    }
  }
  rig.gauge = rig.shear ? sp.thickness_m : sp.length_m;
  rig.area = rig.shear ? sp.length_m * sp.width_m : sp.width_m * sp.thickness_m;
  return rig;
}

/// The specimen's instantaneous elastic stress at each strain (static solves in order, each from
/// the last), with the GPS's energy map of the stiffening shape with b and the compression ratio r.
std::vector<double> static_curve(const Rig& rig, double modulus_pa, StiffeningShape shape, double b, double r, const std::vector<double>& strains) {
  GpsOptions options;
  options.variant = GpsVariant::energy_consistent;
  options.mechanisms.stiffening = {b, GpsStiffening::Form::energy, shape};
  options.mechanisms.asymmetry.compression_ratio = r;
  const GpsModel model(rig.mesh, {specimen_elasticity(modulus_pa, rig.shear)}, {}, options);
  double strain = 0.0;
  BoundaryConditions bc = rig.bc;
  bc.prescribed_axes.push_back({rig.moving, 0, [&](const Vec3& X, double) { return X.x() + strain * (rig.shear ? X.z() : X.x()); }});
  ImplicitIntegrator integrator(model, std::vector<double>(rig.mesh->tet_count(), 1000.0), bc, {1e-3, 0.0, 1e-8, 50});
  State s = State::at_rest(*rig.mesh);
  std::vector<double> stress;
  // Static solve at strain `to` from the converged state at `strain`; where Newton does not
  // converge (strong stiffening far from the last state), reach it through the midpoint first.
  const std::function<void(double, int)> solve_at = [&](double to, int depth) {
    const State before = s;
    const double from = strain;
    strain = to;
    try {
      integrator.solve_static(s);
    } catch (const SimulationError&) {
      if (depth >= 10) throw;
      s = before;
      strain = from;
      solve_at(0.5 * (from + to), depth + 1);
      solve_at(to, depth + 1);
    }
  };
  for (const double e : strains) {
    if (e * strain < 0) {  // the other side of rest: start again from it
      s = State::at_rest(*rig.mesh);
      strain = 0.0;
    }
    solve_at(e, 0);
    double reaction = 0.0;
    for (auto i : rig.moving) reaction -= integrator.last_internal_forces()[i].x();
    stress.push_back(reaction / rig.area);
  }
  return stress;
}

}  // namespace

ShapeCalibration calibrate_elastic_shape(const MaterialModel& m, const Dataset& d) {
  ShapeCalibration c;
  const bool stiffens = m.has(Mechanism::strain_stiffening) && m.stiffening_b > 0;
  const bool asymmetric = m.has(Mechanism::tension_compression_asymmetry) && m.compression_ratio != 1.0;
  c.law_b = c.gps_b = stiffens ? m.stiffening_b : 0.0;
  c.law_r = c.gps_r = asymmetric ? m.compression_ratio : 1.0;
  if (!stiffens && !asymmetric) return c;
  // The tissue's own curve over the strains the specimen itself went through (after a platens' gap).
  MaterialModel tissue = m;
  tissue.mechanisms &= ~(1u << static_cast<unsigned>(Mechanism::contact_take_up));
  for (const auto& t : d.tests)
    for (const double e : t.strain) {
      c.strain_lo = std::min(c.strain_lo, specimen_strain(m, e));
      c.strain_hi = std::max(c.strain_hi, specimen_strain(m, e));
    }
  // Six strains on each side of rest that the data reach, from 0 outwards (each static solve
  // starts from the last).
  std::vector<double> tension, compression;
  for (int k = 1; k <= 6; ++k) {
    if (c.strain_hi > 1e-6) tension.push_back(c.strain_hi * k / 6.0);
    if (c.strain_lo < -1e-6) compression.push_back(c.strain_lo * k / 6.0);
  }
  const Rig rig = make_rig(d.mode, d.specimen);  // the shape is calibrated on the data set's specimen
  const double E = 1e4;  // the shape is what is calibrated (the stress scales with the modulus)
  const auto law = [&](double e) { return E * ElasticShape{tissue}.value(e); };  // the virgin curve
  const StiffeningShape shape = gps_shape(m.stiffening_form);
  const auto mismatch = [&](double b, double r, const std::vector<double>& strains) {
    if (strains.empty()) return 0.0;
    std::vector<double> curve;
    try {
      curve = static_curve(rig, E, shape, b, r, strains);
    } catch (const SimulationError&) {
      return std::numeric_limits<double>::infinity();  // the specimen cannot follow this B: not a candidate
    }
    double sq = 0.0, norm = 0.0;
    for (std::size_t k = 0; k < strains.size(); ++k) {
      sq += (curve[k] - law(strains[k])) * (curve[k] - law(strains[k]));
      norm += law(strains[k]) * law(strains[k]);
    }
    return std::sqrt(sq / norm);
  };
  std::vector<double> all = tension;
  all.insert(all.end(), compression.begin(), compression.end());
  if (all.empty()) return c;
  c.uncalibrated_mismatch = mismatch(c.law_b, c.law_r, all);
  // B from the tension side, r from the compression side; twice, since the lateral edges of a
  // stretched specimen are compressed (and those of a compressed one stretched).
  for (int round = 0; round < 2; ++round) {
    // B from the compression side where the data never stretch (a disc between platens).
    const std::vector<double>& b_side = tension.empty() ? compression : tension;
    if (stiffens && !b_side.empty())
      c.gps_b = golden_section([&](double b) { return mismatch(b, c.gps_r, b_side); }, (tension.empty() ? 0.02 : 0.2) * c.law_b,
                               (rig.shear ? 4.0 : 1.5) * c.law_b, 1e-4 * c.law_b)
                    .x;
    if (asymmetric && !compression.empty())
      c.gps_r = std::exp(
          golden_section([&](double lr) { return mismatch(c.gps_b, std::exp(lr), compression); }, std::log(c.law_r / 4), std::log(c.law_r * 4), 1e-4)
              .x);
    if (!(stiffens && asymmetric)) break;
  }
  c.mismatch = mismatch(c.gps_b, c.gps_r, all);
  return c;
}

namespace {

/// The test's loading on the rig's moving face: its strain history prescribed on the moving
/// nodes' x, or its stress history as a traction on the moving face (per pascal, scaled by the
/// history), along its command path (command_path.hpp), which must outlive them.
BoundaryConditions specimen_loading(const Rig& rig, const Specimen& sp, const TestData& t, const CommandPath& path) {
  BoundaryConditions bc = rig.bc;
  const bool shear = rig.shear;
  const double t0 = path.time_s.front();
  if (t.control == Control::strain) {
    bc.prescribed_axes.push_back({rig.moving, 0, [&path, t0, shear](const Vec3& X, double time) {
                                    const double e = path.at(time + t0);
                                    return X.x() + e * (shear ? X.z() : X.x());
                                  }});
    return bc;
  }
  const auto& mesh = *rig.mesh;
  const double eps = 1e-9 * sp.length_m;
  bc.nodal_forces.assign(mesh.node_count(), Vec3::Zero());
  const int normal = shear ? 2 : 0;
  const double face = shear ? sp.thickness_m : sp.length_m;
  for (const auto& tri : extract_boundary(mesh).triangles) {
    bool on = true;
    for (auto v : tri) on = on && mesh.nodes[v][normal] > face - eps;
    if (!on) continue;
    const Vec3 &a = mesh.nodes[tri[0]], &b = mesh.nodes[tri[1]], &c = mesh.nodes[tri[2]];
    for (auto v : tri) bc.nodal_forces[v].x() += 0.5 * (b - a).cross(c - a).norm() / 3.0;  // per pascal
  }
  bc.force_amplitude = [&path, t0](double time) { return path.at(time + t0); };
  return bc;
}

/// Advances to time `end` [s] in steps from 1/8 of the sampling interval `interval` (or 1 ms)
/// growing by 1.6x: small where the history turns, long through holds (backward Euler is stable
/// for any step). A step whose Newton iteration does not converge is retried at a quarter.
/// Past `deadline` it stops with a SimulationError saying where it was.
void advance_to(ImplicitIntegrator& integrator, State& s, double end, double interval, double total_s, SpecimenResult& r,
                std::chrono::steady_clock::time_point deadline) {
  double dt = std::min(1e-3, interval / 8);
  while (s.time_s < end - 1e-12) {
    if (std::chrono::steady_clock::now() > deadline) {
      char text[300];
      std::snprintf(text, sizeof text,
                    "stopped at its time limit at t = %.4g s of %.4g s of the test (%ld steps, %ld step cuts, %ld Newton iterations)", s.time_s,
                    total_s, r.steps, r.step_cuts, r.newton_iterations);
      throw SimulationError(text);
    }
    dt = std::min(dt, end - s.time_s);
    integrator.set_dt(dt);
    try {
      r.newton_iterations += integrator.step(s).iterations;
    } catch (const SimulationError&) {
      // Newton did not converge: the state is unchanged; retry with a quarter of the step.
      if (dt < 1e-9 * (total_s + 1)) throw;
      dt /= 4;
      ++r.step_cuts;
      continue;
    }
    ++r.steps;
    dt *= 1.6;
  }
}

}  // namespace

GpsLaw gps_law(const MaterialModel& m, const Dataset& d, const ShapeCalibration* calibration) {
  GpsLaw law;
  GpsMechanisms& ve = law.mechanisms;
  double relaxing = 0.0;
  if (m.has(Mechanism::broadband_relaxation))
    for (std::size_t l = 0; l < m.relaxation_time_s.size(); ++l)
      if (m.relaxation_modulus_pa[l] > 0) relaxing += m.relaxation_modulus_pa[l];
  const double E_u = m.modulus_pa + relaxing;
  if (m.has(Mechanism::broadband_relaxation))
    for (std::size_t l = 0; l < m.relaxation_time_s.size(); ++l)
      if (m.relaxation_modulus_pa[l] > 0) {
        ve.viscous.omega_rad_s.push_back(1.0 / m.relaxation_time_s[l]);
        ve.viscous.shear_weight.push_back(m.relaxation_modulus_pa[l] / E_u);
      }
  ve.viscous.kelvin_voigt_time_s = m.viscosity_pa_s / E_u;
  if (m.has(Mechanism::first_load_softening)) ve.softening.d = m.softening_d;
  if (m.has(Mechanism::strain_stiffening) || m.has(Mechanism::tension_compression_asymmetry)) {
    law.shape = calibration ? *calibration : calibrate_elastic_shape(m, d);
    ve.stiffening = {law.shape.gps_b, GpsStiffening::Form::energy, gps_shape(m.stiffening_form)};
    ve.asymmetry.compression_ratio = law.shape.gps_r;
  }
  law.unrelaxed_modulus_pa = E_u;
  return law;
}

SpecimenResult simulate_specimen(const MaterialModel& m, const Dataset& d, const TestData& t, const ShapeCalibration* calibration,
                                 double max_seconds) {
  SpecimenResult r;
  r.supported = specimen_supports(m, d.mode, &r.note);
  if (!r.supported) return r;
  const GpsLaw law = gps_law(m, d, calibration);
  const std::string note = r.note;
  // The test's part: the specimen is compressed by what is left after the platens' gap, and the
  // platens do not pull.
  const bool fixture = m.has(Mechanism::contact_take_up) && t.control == Control::strain;
  TestData on_specimen = t;
  if (fixture)
    for (double& e : on_specimen.strain) e = specimen_strain(m, e);
  r = simulate_specimen(law.mechanisms, specimen_elasticity(law.unrelaxed_modulus_pa, d.mode == Mode::simple_shear), d, on_specimen, max_seconds);
  if (m.platens && t.control == Control::strain) {
    double sq = 0.0;
    for (std::size_t k = 0; k < r.stress_pa.size(); ++k) {
      r.stress_pa[k] = std::min(0.0, r.stress_pa[k]);
      r.strain[k] = t.strain[k];
      sq += (r.stress_pa[k] - t.stress_pa[k]) * (r.stress_pa[k] - t.stress_pa[k]);
    }
    if (!r.stress_pa.empty()) r.rms_pa = std::sqrt(sq / static_cast<double>(r.stress_pa.size()));
  }
  r.note = note;
  r.shape = law.shape;
  return r;
}

SpecimenResult simulate_specimen(const GpsMechanisms& mechanisms, const Mat6& unrelaxed_elasticity, const Dataset& d, const TestData& t,
                                 double max_seconds) {
  const auto deadline = max_seconds > 0
                            ? std::chrono::steady_clock::now() +
                                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(max_seconds))
                            : std::chrono::steady_clock::time_point::max();
  SpecimenResult r;
  r.supported = true;
  const Specimen& sp = specimen_of(d, t);
  const Rig rig = make_rig(d.mode, sp);
  const auto& mesh = rig.mesh;
  GpsOptions options;
  options.variant = GpsVariant::energy_consistent;
  options.mechanisms = mechanisms;
  const GpsModel model(mesh, {unrelaxed_elasticity}, {}, options);
  const CommandPath path = command_path(t.time_s, t.control == Control::strain ? t.strain : t.stress_pa);
  ImplicitIntegrator integrator(model, std::vector<double>(mesh->tet_count(), sp.density_kg_m3), specimen_loading(rig, sp, t, path),
                                {1e-3, 0.0, 1e-8, 25, kSpecimenResidualToNoise * noise_level_pa(t) * rig.area});
  State s = State::at_rest(*mesh);
  // The command path's start is taken as an equilibrium state, as the material-point law does: grip (or
  // load) at its first value, solved statically, memory variables fully relaxed there.
  integrator.solve_static(s);
  s.memory.assign(model.memory_size(), 0.0);
  {
    std::vector<Vec3> f(mesh->node_count(), Vec3::Zero());
    model.add_forces(s.x, f, {s.memory, s.memory, 1e12});
  }
  // The measured quantities: the moving face's reaction per area [Pa] and its mean displacement
  // over the gauge (the strain).
  std::vector<Vec3> forces;
  const auto measure = [&](bool first) {
    if (first) {
      std::vector<double> scratch(model.memory_size());
      forces.assign(mesh->node_count(), Vec3::Zero());
      model.add_forces(s.x, forces, {s.memory, scratch, 0.0});
    } else {
      forces = integrator.last_internal_forces();
    }
    double reaction = 0.0, u = 0.0;
    for (auto i : rig.moving) {
      reaction -= forces[i].x();
      u += s.x[i].x() - mesh->nodes[i].x();
    }
    return std::pair{reaction / rig.area, u / static_cast<double>(rig.moving.size()) / rig.gauge};
  };
  const double t0 = path.time_s.front(), equivalent = apparent_modulus_pa(t);  // strain error -> equivalent stress, as the law's
  double sq = 0.0;
  // Point to point along the path, so that no step straddles one of its corners.
  std::size_t k = 0;
  for (std::size_t j = 0; j < path.time_s.size(); ++j) {
    if (j > 0) advance_to(integrator, s, path.time_s[j] - t0, path.time_s[j] - path.time_s[j - 1], path.time_s.back() - t0, r, deadline);
    if (path.sample[k] != j) continue;
    const auto [stress, strain] = measure(r.steps == 0);
    if (t.control == Control::strain) {
      r.stress_pa.push_back(stress);
      r.strain.push_back(t.strain[k]);
      sq += (stress - t.stress_pa[k]) * (stress - t.stress_pa[k]);
    } else {
      r.stress_pa.push_back(t.stress_pa[k]);
      r.strain.push_back(strain);
      sq += (strain - t.strain[k]) * (strain - t.strain[k]) * equivalent * equivalent;
    }
    ++k;
  }
  r.rms_pa = std::sqrt(sq / static_cast<double>(t.time_s.size()));
  return r;
}

}  // namespace viscera::lab
