// viscera._viscera.tissue: an organ for researchers, built as viscera-sim builds it (mesh,  // SPDX-License-Identifier: Apache-2.0
// material file or isotropic parameters, a force model, fixed nodes, an integrator), stepped from
// Python; positions and velocities are numpy views of the state, never copies.
#include <algorithm>
#include <chrono>
#include <cmath>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "viscera/common/command_line.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

#include "bindings.hpp"
#include "numpy_views.hpp"

namespace viscera::python {

namespace {

using namespace viscera::tissue;
using common::UsageError;

struct OrganOptions {
  std::string mesh, material;
  double scale = 1, youngs_modulus_pa = 5000, poisson_ratio = 0.45, density_kg_m3 = 1060;
  std::string model = "gps_energy", integrator = "explicit";
  double volume_term = 0.5, damping_per_s = 5, dt_s = 0.01;
  std::vector<std::int32_t> fixed_nodes;
  Vec3 gravity_m_s2{0, 0, -9.81};
};

class Organ {
 public:
  explicit Organ(const OrganOptions& o) : mesh_(std::make_shared<TetMesh>(read_tet_mesh(o.mesh))) {
    if (!(o.scale > 0)) throw UsageError("scale must be positive, not " + std::to_string(o.scale));
    scale_mesh(*mesh_, o.scale);
    Material material;
    if (!o.material.empty()) {
      material = read_material_file(o.material);
    } else {
      // The ranges a material file has (docs/MATERIAL.md): E = 1e30 was accepted, and its stable
      // step made advance(0.01) run for more than ten minutes.
      if (!(o.youngs_modulus_pa >= 1e-3 && o.youngs_modulus_pa <= 1e12))
        throw UsageError("youngs_modulus_pa: " + std::to_string(o.youngs_modulus_pa) + " is outside [1e-3, 1e12] Pa");
      if (!(o.poisson_ratio >= -0.9999 && o.poisson_ratio <= 0.4999))
        throw UsageError("poisson_ratio: " + std::to_string(o.poisson_ratio) + " is outside [-0.9999, 0.4999]");
      if (!(o.density_kg_m3 > 0 && o.density_kg_m3 <= 1e5)) throw UsageError("density_kg_m3 must lie in (0, 1e5]");
      material.name = "isotropic";
      material.density_kg_m3 = o.density_kg_m3;
      material.elasticity = elasticity_matrix(IsotropicElasticity{o.youngs_modulus_pa, o.poisson_ratio}, "Organ");
    }
    if (!(o.volume_term >= 0 && o.volume_term < 1)) throw UsageError("volume_term must lie in [0, 1)");
    if (!(o.damping_per_s >= 0)) throw UsageError("damping_per_s must be at least 0");
    Mat6 elasticity = material.elasticity;
    GpsMechanisms mechanisms;
    if (material.viscoelasticity) {
      const ViscoelasticSetup ve = make_viscoelastic(material.elasticity, *material.viscoelasticity, o.material);
      elasticity = ve.unrelaxed_elasticity;
      mechanisms = ve.gps;
    }
    model_ = make_force_model(o.model, mesh_, {elasticity}, o.volume_term, mechanisms);
    BoundaryConditions bc;
    bc.gravity_m_s2 = o.gravity_m_s2;
    for (const auto i : o.fixed_nodes)
      if (i < 0 || static_cast<std::size_t>(i) >= mesh_->node_count())
        throw UsageError("fixed_nodes: " + std::to_string(i) + " is not a node index in [0, " + std::to_string(mesh_->node_count() - 1) + "]");
    bc.fixed_nodes = o.fixed_nodes;
    std::sort(bc.fixed_nodes.begin(), bc.fixed_nodes.end());
    bc.fixed_nodes.erase(std::unique(bc.fixed_nodes.begin(), bc.fixed_nodes.end()), bc.fixed_nodes.end());
    const std::vector<double> rho(mesh_->tet_count(), material.density_kg_m3);
    if (o.integrator == "explicit") {
      explicit_ = std::make_unique<ExplicitIntegrator>(*model_, rho, bc, ExplicitOptions{0.9, 0.0, o.damping_per_s, 2.0});
    } else if (o.integrator == "implicit") {
      if (!(o.dt_s > 0)) throw UsageError("dt_s must be positive");
      implicit_dt_s_ = o.dt_s;
      implicit_ = std::make_unique<ImplicitIntegrator>(*model_, rho, bc, ImplicitOptions{o.dt_s, o.damping_per_s, 1e-8, 50});
    } else {
      throw UsageError("integrator: '" + o.integrator + "' is not explicit or implicit");
    }
    state_ = State::at_rest(*mesh_);
    name_ = material.name;
  }

  /// Advances by `duration_s`; returns the steps taken. Ctrl-C (any Python signal handler that
  /// raises) stops it between steps, within 0.1 s, and raises there.
  long advance(double duration_s) {
    if (!(duration_s >= 0 && std::isfinite(duration_s))) throw UsageError("duration_s must be a finite time of at least 0 s");
    if (explicit_) {
      explicit_->set_interruption([this] { return signalled(); });
      const long steps = explicit_->advance(state_, duration_s);
      explicit_->set_interruption({});
      if (interrupted_) throw_interrupted();
      return steps;
    }
    long steps = 0;
    const double end = state_.time_s + duration_s;
    while (state_.time_s < end - 1e-12) {
      if (signalled()) throw_interrupted();
      implicit_->set_dt(std::min(implicit_dt_s_, end - state_.time_s));
      implicit_->step(state_);
      ++steps;
    }
    return steps;
  }

  /// Whether Python has a signal to raise (Ctrl-C): asked at most every 0.1 s, with the GIL.
  bool signalled() {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_signal_check_ < std::chrono::milliseconds(100)) return interrupted_;
    last_signal_check_ = now;
    pybind11::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) interrupted_ = true;
    return interrupted_;
  }
  [[noreturn]] void throw_interrupted() {
    interrupted_ = false;
    pybind11::gil_scoped_acquire gil;
    throw pybind11::error_already_set();  // the KeyboardInterrupt the signal handler set
  }

  void set_nodal_forces(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& f) {
    if (static_cast<std::size_t>(f.rows()) != mesh_->node_count())
      throw UsageError("nodal forces: " + std::to_string(f.rows()) + " rows for " + std::to_string(mesh_->node_count()) + " nodes");
    std::vector<Vec3> forces(mesh_->node_count());
    for (std::size_t i = 0; i < forces.size(); ++i) forces[i] = f.row(static_cast<Eigen::Index>(i)).transpose();
    if (explicit_)
      explicit_->boundary_conditions().nodal_forces = std::move(forces);
    else
      throw UsageError("nodal forces: the implicit integrator takes its loads at construction; use the explicit integrator");
  }

  /// (tets, 6) engineering strains (L - L0) / L0 of each tetrahedron's edges, in the GPS's order
  /// (01, 02, 03, 12, 13, 23).
  std::vector<double> edge_strains() const {
    static constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    std::vector<double> out(mesh_->tet_count() * 6);
    for (std::size_t e = 0; e < mesh_->tet_count(); ++e) {
      const auto& t = mesh_->tets[e];
      for (int k = 0; k < 6; ++k) {
        const auto a = static_cast<std::size_t>(t[static_cast<std::size_t>(kEdges[k][0])]);
        const auto b = static_cast<std::size_t>(t[static_cast<std::size_t>(kEdges[k][1])]);
        const double l0 = (mesh_->nodes[a] - mesh_->nodes[b]).norm();
        out[6 * e + static_cast<std::size_t>(k)] = ((state_.x[a] - state_.x[b]).norm() - l0) / l0;
      }
    }
    return out;
  }

  std::shared_ptr<TetMesh> mesh_;
  std::unique_ptr<ForceModel> model_;
  std::unique_ptr<ExplicitIntegrator> explicit_;
  std::unique_ptr<ImplicitIntegrator> implicit_;
  std::chrono::steady_clock::time_point last_signal_check_{};
  bool interrupted_ = false;
  double implicit_dt_s_ = 0;
  State state_;
  std::string name_;
};

py::array_t<double> vec3_view(const std::vector<Vec3>& v, py::handle owner) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  return view_array<double>(v.data()->data(), {static_cast<py::ssize_t>(v.size()), 3}, {sizeof(Vec3), sizeof(double)}, owner);
}

}  // namespace

void bind_tissue(py::module_& m) {
  py::class_<Organ>(m, "Organ",
                    "An organ mesh with a material, a force model, fixed nodes and an integrator (as viscera-sim builds it). "
                    "SI units: metres, seconds, pascals, kilograms, newtons.")
      .def(py::init([](const std::string& mesh, const std::string& material, double scale, double youngs_modulus_pa, double poisson_ratio,
                       double density_kg_m3, const std::string& model, double volume_term, std::vector<std::int32_t> fixed_nodes,
                       std::array<double, 3> gravity, double damping_per_s, const std::string& integrator, double dt_s) {
             OrganOptions o{mesh,
                            material,
                            scale,
                            youngs_modulus_pa,
                            poisson_ratio,
                            density_kg_m3,
                            model,
                            integrator,
                            volume_term,
                            damping_per_s,
                            dt_s,
                            std::move(fixed_nodes),
                            Vec3(gravity[0], gravity[1], gravity[2])};
             py::gil_scoped_release unlocked;  // the GPS calibration of a large mesh takes a while
             return std::make_unique<Organ>(o);
           }),
           py::arg("mesh"), py::kw_only(), py::arg("material") = "", py::arg("scale") = 1.0, py::arg("youngs_modulus_pa") = 5000.0,
           py::arg("poisson_ratio") = 0.45, py::arg("density_kg_m3") = 1060.0, py::arg("model") = "gps_energy", py::arg("volume_term") = 0.5,
           py::arg("fixed_nodes") = std::vector<std::int32_t>{}, py::arg("gravity_m_s2") = std::array<double, 3>{0, 0, -9.81},
           py::arg("damping_per_s") = 5.0, py::arg("integrator") = "explicit", py::arg("dt_s") = 0.01)
      .def_property_readonly(
          "node_count", [](const Organ& o) { return o.mesh_->node_count(); }, "nodes of the mesh")
      .def_property_readonly(
          "tet_count", [](const Organ& o) { return o.mesh_->tet_count(); }, "tetrahedra of the mesh")
      .def_property_readonly(
          "model", [](const Organ& o) { return std::string(o.model_->name()); }, "the force model's name")
      .def_property_readonly(
          "material", [](const Organ& o) { return o.name_; }, "the material's name")
      .def_property_readonly(
          "time_s", [](const Organ& o) { return o.state_.time_s; }, "[s] simulated time")
      .def_property_readonly(
          "dt_s", [](const Organ& o) { return o.explicit_ ? o.explicit_->dt_s() : o.implicit_dt_s_; }, "[s] the step")
      .def_property_readonly(
          "rest_positions", [](const py::object& self) { return vec3_view(self.cast<const Organ&>().mesh_->nodes, self); }, "(nodes, 3) [m], a view")
      .def_property_readonly(
          "positions", [](const py::object& self) { return vec3_view(self.cast<const Organ&>().state_.x, self); },
          "(nodes, 3) [m], a read-only view of the state (valid while the organ lives; it changes as the organ steps)")
      .def_property_readonly(
          "velocities", [](const py::object& self) { return vec3_view(self.cast<const Organ&>().state_.v, self); }, "(nodes, 3) [m/s], a view")
      .def_property_readonly(
          "tets",
          [](const py::object& self) {
            const auto& t = self.cast<const Organ&>().mesh_->tets;
            return view_array<std::int32_t>(t.data()->data(), {static_cast<py::ssize_t>(t.size()), 4}, {sizeof(t[0]), sizeof(std::int32_t)}, self);
          },
          "(tets, 4) node indices, a view")
      .def("advance", &Organ::advance, py::arg("duration_s"), py::call_guard<py::gil_scoped_release>(),
           "Advances by duration_s [s] in steps of at most dt_s; returns the steps taken. Raises SimulationError when it goes unstable.")
      .def("set_nodal_forces", &Organ::set_nodal_forces, py::arg("forces_n"), "External forces [N], a (nodes, 3) array (explicit integrator).")
      .def(
          "edge_strains",
          [](const Organ& o) {
            auto s = o.edge_strains();
            const auto n = static_cast<py::ssize_t>(o.mesh_->tet_count());
            return owning_array(std::move(s), {n, 6});
          },
          "(tets, 6) engineering strains (L - L0) / L0 of the edges 01, 02, 03, 12, 13, 23")
      .def(
          "nodes_in_box",
          [](const Organ& o, std::array<double, 3> lo, std::array<double, 3> hi) {
            return nodes_in_box(*o.mesh_, Box{Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2])});
          },
          py::arg("low_m"), py::arg("high_m"), "Indices of the nodes inside the box [m], at rest.");
  m.def("force_model_names", &force_model_names);
}

}  // namespace viscera::python
