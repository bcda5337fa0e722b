# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the Python package's tests: the build and source trees (VISCERA_BUILD,
VISCERA_SOURCE, set by ctest), a DDS domain of the test run's own, a real viscera-server on the
liver scene, and a session recorded by viscera-record while a Python client presses the liver."""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, List, Tuple

import pytest

import viscera

BUILD = Path(os.environ.get("VISCERA_BUILD", Path(__file__).resolve().parents[2] / "build"))
SOURCE = Path(os.environ.get("VISCERA_SOURCE", Path(__file__).resolve().parents[2]))


def program(*parts: str) -> str:
    path = BUILD.joinpath(*parts)
    assert path.exists(), f"{path} is not built"
    return str(path)


@pytest.fixture(scope="session")
def domain() -> int:
    os.environ["CYCLONEDDS_URI"] = f"file://{SOURCE}/deploy/dds/loopback.xml"
    return random.randint(1, 200)


@pytest.fixture(scope="session")
def scene_file(tmp_path_factory: pytest.TempPathFactory, domain: int) -> Path:
    scene = json.loads((SOURCE / "data/scenes/liver.json").read_text())
    scene["domain_id"] = domain
    for key in ("mesh", "material"):
        scene["organ"][key] = str(SOURCE / "data" / scene["organ"][key].removeprefix("../"))
    folder = tmp_path_factory.mktemp("scene")
    path = folder / "liver.json"
    path.write_text(json.dumps(scene))
    # The finer liver beside it, in the server's scene directory: load_scene("liver-12k").
    fine = json.loads((SOURCE / "data/scenes/liver-12k.json").read_text())
    fine["domain_id"] = domain
    for key in ("mesh", "material"):
        fine["organ"][key] = str(SOURCE / "data" / fine["organ"][key].removeprefix("../"))
    (folder / "liver-12k.json").write_text(json.dumps(fine))
    return path


class Server:
    def __init__(self, process: "subprocess.Popen[bytes]", log: Path) -> None:
        self.process = process
        self.log = log


@pytest.fixture(scope="session")
def server(scene_file: Path, domain: int, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    log = tmp_path_factory.mktemp("server") / "server.log"
    with open(log, "wb") as out:
        p = subprocess.Popen([program("server/runtime/viscera-server"), "--scene", str(scene_file)], stdout=out, stderr=subprocess.STDOUT)
    try:
        probe = viscera.session.Client(domain, 900)
        assert probe.wait_for_scene(20.0) is not None, f"no scene state from viscera-server: {log.read_text()}"
        del probe
        yield Server(p, log)
    finally:
        p.terminate()
        p.wait(10)


def press_point(client: viscera.session.Client) -> Tuple[float, float, float]:
    """Where a vertical press meets the organ: the centre of its bounds in x and y, at the height of
    the highest rest-surface vertex within 1 cm of it [m]."""
    scene = client.scene()
    assert scene is not None
    cx = 0.5 * (scene.bounds_min_m[0] + scene.bounds_max_m[0])
    cy = 0.5 * (scene.bounds_min_m[1] + scene.bounds_max_m[1])
    for _ in range(200):
        s = client.surface()
        if s is not None:
            rest = s.rest_positions
            near = rest[(rest[:, 0] - cx) ** 2 + (rest[:, 1] - cy) ** 2 < 0.01**2]
            assert len(near) > 0, "no surface vertex within 1 cm of the centre"
            return (cx, cy, float(near[:, 2].max()))
        time.sleep(0.05)
    raise AssertionError("the surface topology never arrived")


class PressLog:
    """What the pressing client sent and received: the commands, and in contact the force along z
    [N] with the depth of the commanded tip's lowest point below the rest surface [m]."""

    def __init__(self) -> None:
        self.commands = 0
        self.forces_z: List[float] = []
        self.depths: List[float] = []


def press(client: viscera.session.Client, instrument: int, seconds: float, depth_m: float, rate_hz: float = 1000.0) -> PressLog:
    """Presses the organ vertically at press_point: the probe's tip (radius 6 mm) from 3 mm above
    the surface down to depth_m below it in the first half, back up in the second, at rate_hz,
    waiting for each force; returns what it saw."""
    top = press_point(client)
    above = 0.006 + 0.003
    log = PressLog()
    start = time.monotonic()
    period = 1.0 / rate_hz
    next_t = start
    while True:
        t = time.monotonic() - start
        if t >= seconds:
            break
        phase = t / seconds
        depth = (depth_m + above) * (1 - abs(2 * phase - 1)) - above  # the tip's lowest point below the surface
        client.send_tip(instrument, [top[0], top[1], top[2] + 0.006 - depth])
        log.commands += 1
        f = client.wait_force(instrument, 0.005)
        if f is not None and f.in_contact:
            log.forces_z.append(f.force_n[2])
            log.depths.append(depth)
        next_t += period
        pause = next_t - time.monotonic()
        if pause > 0:
            time.sleep(pause)
    return log


@dataclass
class Session:
    log: PressLog
    recording: Path
    client_id: int
    round_trip: viscera.session.LatencyStats
    events: list[viscera.session.Event]
    frame: viscera.session.MeshFrame | None
    topology: viscera.session.SurfaceTopology


@pytest.fixture(scope="session")
def session(server: Server, domain: int, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Session]:
    folder = tmp_path_factory.mktemp("recording")
    out = folder / "session.mcap"
    with open(folder / "record.log", "wb") as rec_log:
        recorder = subprocess.Popen([program("tools/viscera-record/viscera-record"), "--out", str(out), "--domain", str(domain)], stdout=rec_log,
                                    stderr=subprocess.STDOUT)
    try:
        c = viscera.session.Client(domain, 31)
        scene = c.wait_for_scene(10.0)
        assert scene is not None and scene.name == "liver"
        c.poll_events()  # subscribes
        press_point(c)
        topology = c.surface()
        assert topology is not None
        time.sleep(1.0)  # the recorder's readers discovered
        claimed = c.claim(1, 3.0)
        assert claimed, claimed.why
        c.annotate("python: start of the press")
        log = press(c, 1, seconds=10.0, depth_m=0.012)
        frame = c.poll_mesh_frame()
        c.release(1)
        time.sleep(0.5)
        events = c.poll_events()
        round_trip = c.round_trip()
        del c
    finally:
        recorder.send_signal(signal.SIGINT)
        assert recorder.wait(30) == 0, (folder / "record.log").read_text()
    yield Session(log, out, 31, round_trip, events, frame, topology)
