# SPDX-License-Identifier: Apache-2.0
"""A scene loaded while a Python client watches: the frames' shape follows the new surface, and
taking a frame's positions copies nothing (tracemalloc sees numpy's allocations). Run last in
python.session: the server then runs the 12k liver."""

from __future__ import annotations

import time
import tracemalloc

import viscera
from conftest import Server


def test_frames_follow_a_scene_change_without_copies(server: Server, domain: int) -> None:
    c = viscera.session.Client(domain, 71)
    before = c.wait_for_scene(10.0)
    assert before is not None
    old = None
    for _ in range(100):
        old = c.surface()
        if old is not None:
            break
        time.sleep(0.05)
    assert old is not None
    outcome = c.load_scene("liver-12k", 120.0)
    assert outcome is not None and outcome.accepted, outcome
    frame = None
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        f = c.poll_mesh_frame()
        if f is not None and f.mesh_id != old.mesh_id:
            frame = f
            break
        time.sleep(0.02)
    assert frame is not None, "no frame of the new scene's surface"
    topology = c.surface()
    assert topology is not None and topology.mesh_id == frame.mesh_id
    assert topology.vertex_count > old.vertex_count
    tracemalloc.start()
    start = tracemalloc.get_traced_memory()[0]
    positions = frame.positions
    allocated = tracemalloc.get_traced_memory()[0] - start
    copy = positions.copy()  # what a copy would have cost: the measurement sees it
    copied = tracemalloc.get_traced_memory()[0] - start - allocated
    tracemalloc.stop()
    assert copied >= copy.nbytes
    assert positions.shape == (topology.vertex_count, 3)
    assert allocated < 0.01 * positions.nbytes, f"taking {positions.nbytes} bytes of positions allocated {allocated}"
    scene = c.scene()
    assert scene is not None and scene.name == "liver-12k" and scene.generation > before.generation
