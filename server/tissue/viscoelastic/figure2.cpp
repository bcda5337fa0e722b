#include "viscera/tissue/viscoelastic/figure2.hpp"  // SPDX-License-Identifier: Apache-2.0

#include <cmath>

#include "viscera/tissue/gps/gps_model.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/box_mesh.hpp"
#include "viscera/tissue/viscoelastic/constant_q.hpp"
#include "viscera/tissue/viscoelastic/shear_layer.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

namespace viscera::tissue {

namespace {

std::vector<double> simulate_gps_block(const Figure2Options& o, const std::function<double(double)>& traction, std::size_t samples, double* dt_out) {
  ShearBlock block = make_shear_block(o, traction);
  ExplicitIntegrator integrator(*block.model, block.density, block.bc);
  *dt_out = integrator.dt_s();
  State s = State::at_rest(*block.mesh);
  std::vector<double> out;
  for (std::size_t k = 0; k < samples; ++k) {
    double u = 0.0;
    for (auto i : block.top) u += s.x[i].x() - block.mesh->nodes[i].x();
    out.push_back(u / static_cast<double>(block.top.size()));
    integrator.advance(s, 1.0 / o.sample_rate_hz);
  }
  return out;
}

double rms_relative(const std::vector<double>& a, const std::vector<double>& ref, double peak) {
  double s = 0.0;
  for (std::size_t k = 0; k < ref.size(); ++k) s += (a[k] - ref[k]) * (a[k] - ref[k]);
  return std::sqrt(s / static_cast<double>(ref.size())) / peak;
}

}  // namespace

ShearBlock make_shear_block(const Figure2Options& o, const std::function<double(double)>& traction) {
  ShearBlock b;
  const double h = o.thickness_m / o.block_layers;
  b.mesh = std::make_shared<TetMesh>(make_box_mesh(Vec3(0, 0, 0), Vec3(h, h, o.thickness_m), 1, 1, o.block_layers));
  const double nu = 0.3;
  ViscoelasticSpec spec;
  spec.shear_q = o.q;
  spec.band_low_hz = o.band_low_hz;
  spec.band_high_hz = o.band_high_hz;
  spec.mechanisms = o.mechanisms;
  spec.reference_frequency_hz = o.reference_frequency_hz;
  const ViscoelasticSetup ve = make_viscoelastic(elasticity_matrix(IsotropicElasticity{2 * o.modulus_pa * (1 + nu), nu}), spec, "figure 2");
  GpsOptions gps_options;
  gps_options.mechanisms = ve.gps;
  b.model = std::make_unique<GpsModel>(b.mesh, std::vector<Mat6>{ve.unrelaxed_elasticity}, std::vector<std::uint16_t>{}, gps_options);
  b.bc.nodal_forces.assign(b.mesh->node_count(), Vec3::Zero());
  for (std::size_t i = 0; i < b.mesh->node_count(); ++i) {
    const auto n = static_cast<std::int32_t>(i);
    if (b.mesh->nodes[i].z() < 1e-12) {
      b.bc.fixed_nodes.push_back(n);
      continue;
    }
    b.bc.fixed_axes.push_back({n, 1});
    b.bc.fixed_axes.push_back({n, 2});
    if (b.mesh->nodes[i].z() > o.thickness_m - 1e-12) b.top.push_back(n);
  }
  for (const auto& tri : extract_boundary(*b.mesh).triangles) {
    const Vec3 &p0 = b.mesh->nodes[tri[0]], &p1 = b.mesh->nodes[tri[1]], &p2 = b.mesh->nodes[tri[2]];
    if (p0.z() < o.thickness_m - 1e-12 || p1.z() < o.thickness_m - 1e-12 || p2.z() < o.thickness_m - 1e-12) continue;
    const double area = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    for (auto v : tri) b.bc.nodal_forces[v].x() += area / 3.0;  // per pascal of traction
  }
  b.bc.force_amplitude = traction;
  b.density.assign(b.mesh->tet_count(), o.density_kg_m3);
  return b;
}

Figure2 compute_figure2(const Figure2Options& o) {
  Figure2 r;
  const double dt = 1.0 / o.sample_rate_hz;
  const auto samples = static_cast<std::size_t>(std::llround(o.end_time_s * o.sample_rate_hz)) + 1;
  const double load = o.load_duration_s;
  // Traction 1 Pa for t < load. The discrete samples place the release at the first sample >= load.
  const auto traction = [load](double t) { return t < load - 1e-12 ? 1.0 : 0.0; };
  for (std::size_t k = 0; k < samples; ++k) r.time_s.push_back(static_cast<double>(k) * dt);

  const ShearLayer layer{o.thickness_m, o.density_kg_m3};
  const ConstantQ cq{o.q, o.modulus_pa, o.reference_frequency_hz};
  const double w0 = 2 * M_PI * o.reference_frequency_hz, g = cq.gamma();
  r.exact_cq_m = exact_top_displacement(
      layer, [&](std::complex<double> s) { return o.modulus_pa * std::pow(s / w0, 2 * g); }, traction, dt, samples);
  // Kelvin-Voigt matched at the reference frequency: Q(w0) = 1 / (w0 tau), |M(w0)| = |G|.
  const double tau = 1.0 / (o.q * w0), G_kv = o.modulus_pa / std::sqrt(1.0 + 1.0 / (o.q * o.q));
  r.kelvin_voigt_m = exact_top_displacement(
      layer, [&](std::complex<double> s) { return G_kv * (1.0 + tau * s); }, traction, dt, samples);
  r.fit = fit_constant_q({o.q, o.band_low_hz, o.band_high_hz, o.mechanisms, o.modulus_pa, o.reference_frequency_hz});
  const ColumnResult column = simulate_memory_column(layer, r.fit.solids, traction, dt, samples, o.column_elements);
  r.memory_variables_m = column.top_displacement_m;
  r.column_dt_s = column.dt_s;
  r.gps_block_m = simulate_gps_block(o, traction, samples, &r.block_dt_s);

  for (double u : r.exact_cq_m) r.peak_m = std::max(r.peak_m, std::abs(u));
  r.rms_memory_variables = rms_relative(r.memory_variables_m, r.exact_cq_m, r.peak_m);
  r.rms_gps_block = rms_relative(r.gps_block_m, r.exact_cq_m, r.peak_m);
  r.rms_kelvin_voigt = rms_relative(r.kelvin_voigt_m, r.exact_cq_m, r.peak_m);
  return r;
}

}  // namespace viscera::tissue
