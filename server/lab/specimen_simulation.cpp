#include "specimen_simulation.hpp"

#include <algorithm>
#include <cmath>

#include "common/input_error.hpp"
#include "gps/gps_model.hpp"
#include "integrator/implicit_integrator.hpp"
#include "material/elasticity.hpp"
#include "mesh/box_mesh.hpp"
#include "mesh/boundary_surface.hpp"

namespace viscera::lab {

using namespace viscera::tissue;

bool specimen_supports(const MaterialModel& m, std::string* why) {
  if (m.has(Mechanism::tension_compression_asymmetry) || m.has(Mechanism::first_load_softening)) {
    *why = "the GPS has no tension/compression asymmetry or first-load softening yet: not simulated on the specimen";
    return false;
  }
  *why = m.has(Mechanism::strain_stiffening)
             ? "Fung stiffening is edge-wise in the GPS, an approximation of the uniaxial law fitted here"
             : "";
  return true;
}

namespace {
double interpolate(const std::vector<double>& t, const std::vector<double>& v, double x) {
  if (x <= t.front()) return v.front();
  if (x >= t.back()) return v.back();
  const auto it = std::upper_bound(t.begin(), t.end(), x);
  const std::size_t k = static_cast<std::size_t>(it - t.begin());
  return v[k - 1] + (v[k] - v[k - 1]) * (x - t[k - 1]) / (t[k] - t[k - 1]);
}
}  // namespace

SpecimenResult simulate_specimen(const MaterialModel& m, const Dataset& d, const TestData& t) {
  SpecimenResult r;
  r.supported = specimen_supports(m, &r.note);
  if (!r.supported) return r;
  const bool shear = d.mode == Mode::simple_shear;
  const Specimen& sp = d.specimen;
  // x: pulling / shearing direction; z: thickness.
  auto mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(sp.length_m, sp.width_m, sp.thickness_m), 2, 1, 1));
  // The fitted law in GPS terms: unrelaxed modulus E_U = E + sum E_l, weights E_l / E_U on both
  // shear and bulk parts (the whole D relaxes alike), Kelvin-Voigt time eta / E_U.
  double relaxing = 0.0;
  GpsViscoelasticity ve;
  if (m.has(Mechanism::broadband_relaxation))
    for (std::size_t l = 0; l < m.relaxation_time_s.size(); ++l)
      if (m.relaxation_modulus_pa[l] > 0) relaxing += m.relaxation_modulus_pa[l];
  const double E_u = m.modulus_pa + relaxing;
  if (m.has(Mechanism::broadband_relaxation))
    for (std::size_t l = 0; l < m.relaxation_time_s.size(); ++l)
      if (m.relaxation_modulus_pa[l] > 0) {
        ve.omega_rad_s.push_back(1.0 / m.relaxation_time_s[l]);
        ve.shear_weight.push_back(m.relaxation_modulus_pa[l] / E_u);
      }
  ve.bulk_weight = ve.shear_weight;
  ve.kelvin_voigt_time_s = m.viscosity_pa_s / E_u;
  if (m.has(Mechanism::strain_stiffening)) ve.qlv_stiffening = m.stiffening_b;
  const double nu = 0.3;
  // Uniaxial: the fitted modulus is Young's; simple shear: it is the shear modulus.
  const double youngs = shear ? 2 * E_u * (1 + nu) : E_u;
  GpsOptions options;
  options.variant = GpsVariant::energy_consistent;
  options.viscoelasticity = ve;
  const GpsModel model(mesh, {elasticity_matrix(IsotropicElasticity{youngs, nu})}, {}, options);

  BoundaryConditions bc;
  std::vector<std::int32_t> moving;
  const double eps = 1e-9 * sp.length_m;
  for (std::size_t i = 0; i < mesh->node_count(); ++i) {
    const Vec3& X = mesh->nodes[i];
    const auto n = static_cast<std::int32_t>(i);
    if (!shear) {
      if (X.x() < eps) {
        bc.fixed_axes.push_back({n, 0});
        if (X.y() < eps && X.z() < eps) bc.fixed_axes.push_back({n, 1}), bc.fixed_axes.push_back({n, 2});
        else if (X.z() < eps) bc.fixed_axes.push_back({n, 2});  // on the y axis: no rotation about x, z
        else if (X.y() < eps) bc.fixed_axes.push_back({n, 1});  // on the z axis: no rotation about y
      }
      if (X.x() > sp.length_m - eps) moving.push_back(n);
    } else {
      if (X.z() < eps) {
        bc.fixed_nodes.push_back(n);
        continue;
      }
      bc.fixed_axes.push_back({n, 1});
      bc.fixed_axes.push_back({n, 2});
      if (X.z() > sp.thickness_m - eps) moving.push_back(n);
    }
  }
  const double gauge = shear ? sp.thickness_m : sp.length_m;
  const double area = shear ? sp.length_m * sp.width_m : sp.width_m * sp.thickness_m;
  const double t0 = t.time_s.front();
  if (t.control == Control::strain) {
    bc.prescribed_axes.push_back({moving, 0, [&, t0](const Vec3& X, double time) {
                                    const double e = interpolate(t.time_s, t.strain, time + t0);
                                    return X.x() + e * (shear ? X.z() : X.x());
                                  }});
  } else {
    bc.nodal_forces.assign(mesh->node_count(), Vec3::Zero());
    const int normal = shear ? 2 : 0;
    const double face = shear ? sp.thickness_m : sp.length_m;
    for (const auto& tri : extract_boundary(*mesh).triangles) {
      bool on = true;
      for (auto v : tri) on = on && mesh->nodes[v][normal] > face - eps;
      if (!on) continue;
      const Vec3 &a = mesh->nodes[tri[0]], &b = mesh->nodes[tri[1]], &c = mesh->nodes[tri[2]];
      for (auto v : tri) bc.nodal_forces[v].x() += 0.5 * (b - a).cross(c - a).norm() / 3.0;  // per pascal
    }
    bc.force_amplitude = [&, t0](double time) { return interpolate(t.time_s, t.stress_pa, time + t0); };
  }
  ImplicitIntegrator integrator(model, std::vector<double>(mesh->tet_count(), sp.density_kg_m3), bc, {1e-3, 0.0, 1e-8, 25});
  State s = State::at_rest(*mesh);
  // The first sample is taken as an equilibrium state, as the material-point law does: grip (or
  // load) at its first value, solved statically, memory variables fully relaxed there.
  integrator.solve_static(s);
  s.memory.assign(model.memory_size(), 0.0);
  {
    std::vector<Vec3> f(mesh->node_count(), Vec3::Zero());
    model.add_forces(s.x, f, {s.memory, s.memory, 1e12});
  }
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
    for (auto i : moving) {
      reaction -= forces[i].x();
      u += s.x[i].x() - mesh->nodes[i].x();
    }
    return std::pair{reaction / area, u / static_cast<double>(moving.size()) / gauge};
  };
  double sq = 0.0;
  for (std::size_t k = 0; k < t.time_s.size(); ++k) {
    if (k > 0) {
      // Steps from 1/8 of the interval (or 1 ms) growing by 1.6x: small where the history turns,
      // long through holds; backward Euler is stable for any step.
      const double end = t.time_s[k] - t0;
      double dt = std::min(1e-3, (t.time_s[k] - t.time_s[k - 1]) / 8);
      while (s.time_s < end - 1e-12) {
        dt = std::min(dt, end - s.time_s);
        integrator.set_dt(dt);
        try {
          r.newton_iterations += integrator.step(s).iterations;
        } catch (const SimulationError&) {
          // Newton did not converge: the state is unchanged; retry with a quarter of the step.
          if (dt < 1e-9 * (t.time_s.back() - t0 + 1)) throw;
          dt /= 4;
          ++r.step_cuts;
          continue;
        }
        ++r.steps;
        dt *= 1.6;
      }
    }
    const auto [stress, strain] = measure(k == 0);
    if (t.control == Control::strain) {
      r.stress_pa.push_back(stress);
      r.strain.push_back(t.strain[k]);
      sq += (stress - t.stress_pa[k]) * (stress - t.stress_pa[k]);
    } else {
      r.stress_pa.push_back(t.stress_pa[k]);
      r.strain.push_back(strain);
      sq += (strain - t.strain[k]) * (strain - t.strain[k]) * E_u * E_u;
    }
  }
  r.rms_pa = std::sqrt(sq / static_cast<double>(t.time_s.size()));
  return r;
}

}  // namespace viscera::lab
