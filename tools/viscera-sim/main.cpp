// viscera-sim: loads an organ mesh and a material, fixes a region, runs it under gravity and  // SPDX-License-Identifier: Apache-2.0
// writes VTU frames (ParaView), printing progress and the step rate.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "viscera/common/command_line.hpp"
#include "viscera/common/existing_output.hpp"
#include "viscera/common/input_error.hpp"
#include "viscera/common/number_text.hpp"
#include "viscera/tissue/integrator/explicit_integrator.hpp"
#include "viscera/tissue/integrator/implicit_integrator.hpp"
#include "viscera/tissue/integrator/simulation_error.hpp"
#include "viscera/tissue/material/elasticity.hpp"
#include "viscera/tissue/material/material_file.hpp"
#include "viscera/tissue/mesh/boundary_surface.hpp"
#include "viscera/tissue/mesh/mesh_reader.hpp"
#include "viscera/tissue/mesh/vtu_writer.hpp"
#include "viscera/tissue/model/model_factory.hpp"
#include "viscera/tissue/viscoelastic/viscoelastic_material.hpp"

using namespace viscera::tissue;
using namespace viscera::common;
namespace fs = std::filesystem;

namespace {

std::vector<std::int32_t> fixed_nodes(const viscera::common::CommandLine& cl, const TetMesh& mesh) {
  std::vector<std::int32_t> fixed;
  const auto box_of = [&](const std::string& flag) {
    const auto v = cl.numbers(flag, 6);
    return Box{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])};
  };
  if (cl.has("fix-box"))
    for (auto i : nodes_in_box(mesh, box_of("fix-box"))) fixed.push_back(i);
  if (cl.has("fix-surface-box"))
    for (auto i : surface_nodes_in_box(mesh, box_of("fix-surface-box"))) fixed.push_back(i);
  if (cl.has("fix-slab")) {
    // AXIS,SIDE,FRACTION: surface nodes within FRACTION of the extent from the min or max side.
    const std::string spec = cl.text("fix-slab");
    const auto c1 = spec.find(','), c2 = spec.find(',', c1 + 1);
    if (c1 == std::string::npos || c2 == std::string::npos)
      throw viscera::common::UsageError("--fix-slab: expected AXIS,SIDE,FRACTION such as y,max,0.1; got '" + spec + "'");
    const std::string axis = spec.substr(0, c1), side = spec.substr(c1 + 1, c2 - c1 - 1);
    const int a = axis == "x" ? 0 : axis == "y" ? 1 : axis == "z" ? 2 : -1;
    if (a < 0) throw viscera::common::UsageError("--fix-slab: axis '" + axis + "' is not x, y or z");
    if (side != "min" && side != "max") throw viscera::common::UsageError("--fix-slab: side '" + side + "' is not min or max");
    std::string why;
    const auto parsed = viscera::common::read_number(std::string_view(spec).substr(c2 + 1), &why);
    if (!parsed) throw viscera::common::UsageError("--fix-slab: fraction " + why);
    const double fraction = *parsed;
    if (!(fraction > 0 && fraction <= 1)) throw viscera::common::UsageError("--fix-slab: fraction must lie in (0, 1]");
    Box b = bounding_box(mesh);
    const double extent = b.hi[a] - b.lo[a];
    if (side == "min")
      b.hi[a] = b.lo[a] + fraction * extent;
    else
      b.lo[a] = b.hi[a] - fraction * extent;
    for (auto i : surface_nodes_in_box(mesh, b)) fixed.push_back(i);
  }
  if (cl.has("fix-nodes")) {
    std::stringstream ss(cl.text("fix-nodes"));
    std::string part;
    while (std::getline(ss, part, ',')) {
      long i = -1;
      try {
        i = std::stol(part);
      } catch (...) {
      }
      if (i < 0 || i >= static_cast<long>(mesh.node_count()))
        throw viscera::common::UsageError("--fix-nodes: '" + part + "' is not a node index in [0, " + std::to_string(mesh.node_count() - 1) + "]");
      fixed.push_back(static_cast<std::int32_t>(i));
    }
  }
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  return fixed;
}

double max_displacement(const State& s, const TetMesh& mesh) {
  double d = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i) d = std::max(d, (s.x[i] - mesh.nodes[i]).norm());
  return d;
}

void declare_flags(viscera::common::CommandLine& cl) {
  cl.flag("mesh", "PATH", "tetrahedral mesh (.msh Gmsh v1/v2/v4.1, .vtk legacy, .vtu)");
  cl.flag("scale", "M_PER_UNIT", "metres per mesh unit (organ meshes carry no units)", "1");
  cl.flag("material", "FILE.json", "material file (docs/MATERIAL.md)");
  cl.flag("youngs-modulus", "PA", "Young's modulus when no --material is given", "5000");
  cl.flag("poisson-ratio", "NU", "Poisson ratio when no --material is given", "0.45");
  cl.flag("density", "KG_M3", "density when no --material is given", "1060");
  cl.flag("model", "NAME", "gps | gps_energy | corotational | linear", "gps_energy");
  cl.flag("volume-term", "FRACTION", "signed-volume stiffness / bulk modulus for the GPS, in [0, 1)", "0.5");
  cl.flag("fix-slab", "AXIS,SIDE,FRACTION", "fix surface nodes within FRACTION of the extent from SIDE (min|max), e.g. y,max,0.15");
  cl.flag("fix-box", "X0,Y0,Z0,X1,Y1,Z1", "fix all nodes inside this box [m]");
  cl.flag("fix-surface-box", "X0,Y0,Z0,X1,Y1,Z1", "fix the surface nodes inside this box [m]");
  cl.flag("fix-nodes", "I,J,...", "fix these node indices (0-based)");
  cl.flag("gravity", "GX,GY,GZ", "gravity [m/s^2]", "0,0,-9.81");
  cl.flag("damping", "PER_S", "mass-proportional damping [1/s]", "5");
  cl.flag("integrator", "NAME", "explicit | implicit", "explicit");
  cl.flag("dt", "S", "time step of the implicit integrator [s] (the explicit step is computed)", "0.01");
  cl.flag("duration", "S", "simulated time [s]", "2");
  cl.flag("frame-rate", "HZ", "VTU frames per simulated second", "30");
  cl.flag("out", "DIR", "output folder for frames (frame_NNNN.vtu + frames.pvd)", "viscera-sim-out");
  cl.option_switch("no-output", "write no frames");
  cl.option_switch("replace", "write into an --out folder that holds files already (frames of the same names are replaced)");
}

/// The organ as the command line describes it: mesh, material, model, boundary conditions and the
/// integrator, printed as they are built.
struct Organ {
  std::shared_ptr<TetMesh> mesh;
  Material material;
  std::unique_ptr<ForceModel> model;
  std::unique_ptr<ExplicitIntegrator> explicit_integrator;
  std::unique_ptr<ImplicitIntegrator> implicit_integrator;
  double implicit_dt_s = 0;
};

Material material_of(const viscera::common::CommandLine& cl) {
  if (cl.has("material")) return read_material_file(cl.text("material"));
  Material material;
  material.name = "command line";
  material.density_kg_m3 = cl.number("density");
  if (!(material.density_kg_m3 > 0)) throw viscera::common::UsageError("--density must be positive");
  material.elasticity = elasticity_matrix(IsotropicElasticity{cl.number("youngs-modulus"), cl.number("poisson-ratio")}, "command line");
  return material;
}

Organ build(const viscera::common::CommandLine& cl) {
  Organ o;
  const std::string mesh_path = cl.text("mesh");
  o.mesh = std::make_shared<TetMesh>(read_tet_mesh(mesh_path));
  const double scale = cl.number("scale");
  if (!(scale > 0)) throw viscera::common::UsageError("--scale must be positive");
  scale_mesh(*o.mesh, scale);
  o.material = material_of(cl);
  const double volume = cl.number_in("volume-term", 0.0, 0.999);
  Mat6 elasticity = o.material.elasticity;
  GpsMechanisms mechanisms;
  if (o.material.viscoelasticity) {
    const ViscoelasticSetup ve = make_viscoelastic(o.material.elasticity, *o.material.viscoelasticity, cl.text("material"));
    std::printf("viscoelasticity\n%s", ve.table.c_str());
    elasticity = ve.unrelaxed_elasticity;
    mechanisms = ve.gps;
  }
  o.model = make_force_model(cl.text("model"), o.mesh, {elasticity}, volume, mechanisms);
  BoundaryConditions bc;
  const auto g = cl.numbers("gravity", 3);
  bc.gravity_m_s2 = Vec3(g[0], g[1], g[2]);
  bc.fixed_nodes = fixed_nodes(cl, *o.mesh);
  const double damping = cl.number_in("damping", 0.0, 1e6);
  const std::string integrator = cl.text("integrator");
  if (integrator != "explicit" && integrator != "implicit")
    throw viscera::common::UsageError("--integrator: '" + integrator + "' is not explicit or implicit");

  const Box box = bounding_box(*o.mesh);
  const Vec3 size = box.hi - box.lo;
  std::printf("mesh      %s: %zu nodes, %zu tetrahedra, %zu surface triangles\n", mesh_path.c_str(), o.mesh->node_count(), o.mesh->tet_count(),
              extract_boundary(*o.mesh).triangles.size());
  std::printf("          scaled by %g m/unit to %.3f x %.3f x %.3f m, volume %.3g m^3, mass %.3g kg\n", scale, size.x(), size.y(), size.z(),
              mesh_volume(*o.mesh), mesh_volume(*o.mesh) * o.material.density_kg_m3);
  std::printf("material  %s, density %g kg/m^3\n", o.material.name.c_str(), o.material.density_kg_m3);
  std::printf("model     %s; %zu fixed nodes; gravity (%g, %g, %g) m/s^2; damping %g 1/s\n", std::string(o.model->name()).c_str(),
              bc.fixed_nodes.size(), g[0], g[1], g[2], damping);
  if (bc.fixed_nodes.empty()) std::printf("warning   no node is fixed: the organ will fall freely\n");

  const std::vector<double> rho(o.mesh->tet_count(), o.material.density_kg_m3);
  if (integrator == "explicit") {
    o.explicit_integrator = std::make_unique<ExplicitIntegrator>(*o.model, rho, bc, ExplicitOptions{0.9, 0.0, damping, 2.0});
    const auto& c = o.explicit_integrator->critical_step();
    std::printf("explicit  critical step %.3g s (element %zu), using %.3g s (safety 0.9)\n", c.dt_s, c.element, o.explicit_integrator->dt_s());
  } else {
    o.implicit_dt_s = cl.number_in("dt", 1e-7, 10);
    o.implicit_integrator = std::make_unique<ImplicitIntegrator>(*o.model, rho, bc, ImplicitOptions{o.implicit_dt_s, damping, 1e-8, 50});
    std::printf("implicit  backward Euler, dt %.3g s, Newton to 1e-8 relative residual, CHOLMOD\n", o.implicit_dt_s);
  }
  return o;
}

/// Frames every 1/frame_rate of simulated time (none when `out` is empty), progress every tenth of
/// the duration.
void simulate(Organ& o, double duration, double frame_rate, const fs::path& out) {
  std::vector<std::pair<double, std::string>> frames;
  State state = State::at_rest(*o.mesh);
  const auto write_frame = [&] {
    if (out.empty()) return;
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04zu.vtu", frames.size());
    write_vtu((out / name).string(), *o.mesh, state.x, state.v);
    frames.emplace_back(state.time_s, name);
  };
  if (!out.empty()) fs::create_directories(out);
  write_frame();
  const auto wall0 = std::chrono::steady_clock::now();
  long steps = 0;
  int newton_total = 0;
  double next_report = 0.0;
  while (state.time_s < duration - 1e-12) {
    const double span = std::min(1.0 / frame_rate, duration - state.time_s);
    if (o.explicit_integrator) {
      steps += o.explicit_integrator->advance(state, span);
    } else {
      const double end = state.time_s + span;
      while (state.time_s < end - 1e-12) {
        o.implicit_integrator->set_dt(std::min(o.implicit_dt_s, end - state.time_s));
        newton_total += o.implicit_integrator->step(state).iterations;
        ++steps;
      }
    }
    write_frame();
    if (state.time_s >= next_report - 1e-12 || state.time_s >= duration - 1e-12) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
      std::printf("t = %6.3f s  %8ld steps  %9.0f steps/s  %6.2fx real time  max displacement %.2f mm%s\n", state.time_s, steps,
                  static_cast<double>(steps) / std::max(wall, 1e-9), state.time_s / std::max(wall, 1e-9), 1e3 * max_displacement(state, *o.mesh),
                  o.implicit_integrator
                      ? (" Newton iterations/step " + std::to_string(static_cast<double>(newton_total) / static_cast<double>(steps))).c_str()
                      : "");
      std::fflush(stdout);
      next_report += 0.1 * duration;
    }
  }
  if (!out.empty()) {
    write_pvd((out / "frames.pvd").string(), frames);
    std::printf("wrote %zu frames to %s (open frames.pvd in ParaView)\n", frames.size(), out.c_str());
  }
}

int run(int argc, char** argv) {
  viscera::common::CommandLine cl("viscera-sim",
                                  "Runs an organ mesh under gravity with a fixed region and writes VTU frames for ParaView.\n"
                                  "Units are SI: metres, seconds, pascals, kilograms.");
  declare_flags(cl);
  if (!cl.parse(argc, argv)) return 0;
  const double duration = cl.number_in("duration", 0.0, 1e6), frame_rate = cl.number_in("frame-rate", 1e-3, 1e4);  // before the slow part
  if (!cl.has("no-output")) viscera::common::refuse_existing_folder(cl.text("out"), cl.has("replace"), "--out");
  Organ organ = build(cl);
  simulate(organ, duration, frame_rate, cl.has("no-output") ? fs::path() : fs::path(cl.text("out")));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const viscera::common::UsageError& e) {
    std::fprintf(stderr, "viscera-sim: %s\n", e.what());
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "viscera-sim: %s\n", e.what());
    return 2;
  } catch (const SimulationError& e) {
    std::fprintf(stderr, "viscera-sim: %s\n", e.what());
    return 3;
  }
}
