# SPDX-License-Identifier: Apache-2.0
"""The tissue core from Python against theory: a bar hanging under its own weight stretches by
rho g L^2 / (2 E) (Poisson ratio 0: the 1-D solution is exact); numpy views of the state."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import viscera


def write_bar(path: Path, length_m: float, side_m: float, n: int) -> None:
    """A legacy VTK bar along z, [0, side]^2 x [0, length], n cells along z, each cube in 6 tets
    (Kuhn), written here so that the mesh does not come from the code under test."""
    nx = 2
    pts = []
    for k in range(n + 1):
        for j in range(nx + 1):
            for i in range(nx + 1):
                pts.append((i * side_m / nx, j * side_m / nx, k * length_m / n))

    def idx(i: int, j: int, k: int) -> int:
        return (k * (nx + 1) + j) * (nx + 1) + i

    tets = []
    paths = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    for k in range(n):
        for j in range(nx):
            for i in range(nx):
                for order in paths:
                    c = [0, 0, 0]
                    chain = [idx(i, j, k)]
                    for axis in order:
                        c[axis] += 1
                        chain.append(idx(i + c[0], j + c[1], k + c[2]))
                    a, b, cc, d = (np.array(pts[v]) for v in chain)
                    if np.dot(np.cross(b - a, cc - a), d - a) < 0:
                        chain[2], chain[3] = chain[3], chain[2]
                    tets.append(chain)
    lines = ["# vtk DataFile Version 3.0", "bar", "ASCII", "DATASET UNSTRUCTURED_GRID", f"POINTS {len(pts)} double"]
    lines += [f"{x} {y} {z}" for x, y, z in pts]
    lines.append(f"CELLS {len(tets)} {5 * len(tets)}")
    lines += ["4 " + " ".join(map(str, t)) for t in tets]
    lines.append(f"CELL_TYPES {len(tets)}")
    lines += ["10"] * len(tets)
    path.write_text("\n".join(lines) + "\n")


def test_hanging_bar_stretches_as_theory_says(tmp_path: Path) -> None:
    length, side, e, rho, g = 0.1, 0.02, 50e3, 1000.0, 9.81
    write_bar(tmp_path / "bar.vtk", length, side, 10)
    probe = viscera.tissue.Organ(str(tmp_path / "bar.vtk"))
    top = probe.nodes_in_box([-1, -1, length - 1e-9], [1, 1, 1])
    assert len(top) == 9
    organ = viscera.tissue.Organ(str(tmp_path / "bar.vtk"), youngs_modulus_pa=e, poisson_ratio=0.0, density_kg_m3=rho, fixed_nodes=top,
                                 gravity_m_s2=[0, 0, -g], integrator="implicit", dt_s=0.02, damping_per_s=40.0, model="gps_energy")
    organ.advance(3.0)
    x = organ.positions
    assert x.shape == (organ.node_count, 3) and not x.flags.writeable
    bottom = organ.rest_positions[:, 2] < 1e-9
    sag = float(np.mean(organ.rest_positions[bottom, 2] - x[bottom, 2]))
    expected = rho * g * length**2 / (2 * e)
    assert sag == pytest.approx(expected, rel=0.03)
    assert np.abs(organ.velocities).max() < 1e-3 * expected / 0.02, "it has come to rest"
    # The view follows the state: it is the organ's memory, not a copy.
    before = x[bottom, 2].copy()
    strains = organ.edge_strains()
    assert strains.shape == (organ.tet_count, 6)
    # Near the top the bar carries its whole weight: strain rho g L / E along z, at most.
    assert strains.max() == pytest.approx(rho * g * length / e, rel=0.15)
    assert np.array_equal(before, organ.positions[bottom, 2])


def test_explicit_steps_and_views_follow_the_state(tmp_path: Path) -> None:
    write_bar(tmp_path / "bar.vtk", 0.05, 0.02, 4)
    organ = viscera.tissue.Organ(str(tmp_path / "bar.vtk"), gravity_m_s2=[0, 0, 0])
    view = organ.positions
    forces = np.zeros((organ.node_count, 3))
    forces[:, 0] = 1e-3  # a uniform push along x, nothing fixed: the body accelerates as a whole
    organ.set_nodal_forces(forces)
    steps = organ.advance(0.1)
    assert steps > 100 and organ.time_s == pytest.approx(0.1)
    shift = view[:, 0] - organ.rest_positions[:, 0]
    assert np.all(shift > 0), "the view shows the new state"
    # Lumped masses computed here: each tetrahedron gives a quarter of rho V to each vertex.
    x0 = organ.rest_positions
    t4 = organ.tets
    volumes = np.abs(np.einsum("ij,ij->i", np.cross(x0[t4[:, 1]] - x0[t4[:, 0]], x0[t4[:, 2]] - x0[t4[:, 0]]), x0[t4[:, 3]] - x0[t4[:, 0]])) / 6
    masses = np.zeros(organ.node_count)
    for k in range(4):
        np.add.at(masses, t4[:, k], 1060.0 * volumes / 4)
    assert masses.sum() == pytest.approx(1060.0 * 0.05 * 0.02 * 0.02)
    # The centre of mass moves as a rigid body with mass-proportional damping a = 5/s:
    # x = F/(m a) (t - (1 - e^{-a t}) / a) (the first-order scheme is (n + 1) / n of it: 1% here).
    a, t, f = 5.0, 0.1, 1e-3 * organ.node_count
    expected = f / (masses.sum() * a) * (t - (1 - np.exp(-a * t)) / a)
    assert float(np.dot(masses, shift) / masses.sum()) == pytest.approx(expected, rel=0.02)


def test_bad_input_names_file_and_field(tmp_path: Path) -> None:
    with pytest.raises(viscera.InputError, match="missing.vtk"):
        viscera.tissue.Organ(str(tmp_path / "missing.vtk"))
    write_bar(tmp_path / "bar.vtk", 0.05, 0.02, 2)
    with pytest.raises(viscera.UsageError, match="fixed_nodes"):
        viscera.tissue.Organ(str(tmp_path / "bar.vtk"), fixed_nodes=[100000])
    with pytest.raises(viscera.UsageError, match="integrator"):
        viscera.tissue.Organ(str(tmp_path / "bar.vtk"), integrator="magic")
    with pytest.raises(viscera.InputError):
        viscera.tissue.Organ(str(tmp_path / "bar.vtk"), model="rubber")
    organ = viscera.tissue.Organ(str(tmp_path / "bar.vtk"))
    with pytest.raises(viscera.UsageError, match="rows"):
        organ.set_nodal_forces(np.zeros((3, 3)))


def test_out_of_range_material_and_times_are_refused(tmp_path: Path) -> None:
    # The ranges a material file has: E = 1e30 was accepted, and advance(0.01) then ran for more
    # than ten minutes (its stable step); advance(inf) returned at once with NaN positions.
    write_bar(tmp_path / "bar.vtk", 0.05, 0.02, 2)
    bar = str(tmp_path / "bar.vtk")
    with pytest.raises(viscera.UsageError, match="youngs_modulus_pa"):
        viscera.tissue.Organ(bar, youngs_modulus_pa=1e30)
    with pytest.raises(viscera.UsageError, match="youngs_modulus_pa"):
        viscera.tissue.Organ(bar, youngs_modulus_pa=float("nan"))
    with pytest.raises(viscera.UsageError, match="poisson_ratio"):
        viscera.tissue.Organ(bar, poisson_ratio=0.5)
    with pytest.raises(viscera.UsageError, match="density_kg_m3"):
        viscera.tissue.Organ(bar, density_kg_m3=1e9)
    organ = viscera.tissue.Organ(str(tmp_path / "bar.vtk"))
    for bad in (float("inf"), float("nan"), -1.0):
        with pytest.raises(viscera.UsageError, match="duration_s"):
            organ.advance(bad)
    assert np.isfinite(organ.positions).all()


def test_ctrl_c_stops_a_long_advance(tmp_path: Path) -> None:
    # advance() releases the interpreter lock; a SIGINT (Ctrl-C) must still stop it, within a
    # fraction of a second, as KeyboardInterrupt, in a child interpreter of its own.
    import os
    import signal
    import subprocess
    import sys
    import time

    write_bar(tmp_path / "bar.vtk", 0.05, 0.02, 8)
    code = ("import sys, time, viscera\n"
            f"o = viscera.tissue.Organ({str(tmp_path / 'bar.vtk')!r}, youngs_modulus_pa=1e9)\n"
            "print('advancing', flush=True)\n"
            "t0 = time.monotonic()\n"
            "try:\n"
            "    o.advance(1e4)\n"
            "except KeyboardInterrupt:\n"
            "    print(f'interrupted {time.monotonic() - t0:.2f}', flush=True)\n"
            "    sys.exit(7)\n")
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=os.environ.copy())
    assert child.stdout is not None
    assert child.stdout.readline().strip() == "advancing"
    time.sleep(0.5)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    rc = child.wait(timeout=10)
    assert rc == 7, f"exit {rc}: {child.stdout.read()}"
    assert time.monotonic() - sent < 2.0
