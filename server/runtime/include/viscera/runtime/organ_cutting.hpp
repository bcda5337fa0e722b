#pragma once  // SPDX-License-Identifier: Apache-2.0
// A scalpel's cut through the running organ (docs/CUTTING.md, "In the server"): the blade's sweep
// over one tick cuts the mesh in place (tissue::MeshCutter), and the force model, the explicit
// integrator, the boundary surface and the contacts' surface follow it, all on the physics thread
// between ticks. Deterministic: the same sweeps on the same state give the same organ, so a
// recorded session with cuts re-simulates bit for bit.
#include <cstdint>
#include <string>

#include "viscera/runtime/organ.hpp"
#include "viscera/tissue/cutting/blade_sweep.hpp"
#include "viscera/tissue/integrator/state.hpp"

namespace viscera::runtime {

/// What one sweep did to the organ.
struct SweepOutcome {
  bool topology_changed = false;  ///< the mesh changed (split, opened)
  bool surface_changed = false;  ///< the boundary surface changed (topology_generation went up)
  std::size_t tets_cut = 0;  ///< tetrahedra of the organ before the sweep that it changed
  std::size_t split_edges = 0, duplicated_nodes = 0;
  double added_mass_kg = 0;  ///< inertia added to keep the new elements' stable step
  /// The kinetic energy of the nodes the sweep touched (the vertices of the elements it replaced,
  /// before and after, new nodes included) and the elastic energy of the elements it replaced, just
  /// before it [J], and the same just after with their children's: nothing else changes, so their
  /// difference is the change of the whole organ's kinetic plus elastic energy (0 and 0 when the
  /// topology did not change).
  double energy_before_j = 0, energy_after_j = 0;
  /// The largest edge strain |L - L0| / L0 of the sweep's new and changed elements just after it:
  /// the tissue where the blade cut (0 when the topology did not change).
  double cut_edge_strain = 0;
  /// Whether the energy rose, beyond rounding (1e-9 of energy_before_j).
  bool energy_rose() const { return energy_after_j - energy_before_j > 1e-9 * energy_before_j + 1e-18; }
};

/// Makes `organ` cuttable when its scene has a scalpel: a MeshCutter on its mesh, and room
/// reserved for the elements cuts make, so a cut rarely reallocates (before anything else reads the
/// model on another thread: the contact compliance's worker). Only the GPS models follow a cut;
/// a scene with a scalpel on another model is refused when it is read (read_scene_file).
void enable_cutting(Organ& organ);

/// Room in `state` (positions, velocities, memory) for what the organ's reserve holds, so that a
/// sweep does not reallocate them (a 2 MB memory vector grown on the 12k liver took 8 ms).
void reserve_for_cuts(const Organ& organ, tissue::State& state);

/// Whether the organ may be cut (its scene has a scalpel and its model follows cuts).
bool can_cut(const Organ& organ);

/// One sweep of a blade through the organ in `state` (its positions now), as part of stroke
/// `stroke`; the state gains the new nodes and memory. Requires can_cut(organ).
SweepOutcome cut_organ(Organ& organ, const tissue::BladeSweep& sweep, tissue::State& state, std::int32_t stroke);

/// The organ's force model calibrated again from scratch on a copy of its (cut) mesh, each element
/// with its material: what following the cuts must have given (tests; the compliance below).
std::unique_ptr<tissue::ForceModel> remake_model(const Organ& organ);

/// The contact compliance of the organ as cut now (docs/CUTTING.md, "The haptic local model"): the
/// mesh, the elements' materials, the inertia and the boundary conditions copied on the calling
/// thread (between ticks), the model made again and factorised on the compliance's worker, so the
/// organ may go on being cut meanwhile. Requires can_cut(organ).
std::unique_ptr<ContactCompliance> rebuild_compliance(const Organ& organ);

}  // namespace viscera::runtime
