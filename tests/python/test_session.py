# SPDX-License-Identifier: Apache-2.0
"""A 10-second session against a real viscera-server over DDS, recorded by viscera-record; the
recording read back into DataFrames and judged against the official MCAP reader's counts and
against what the client itself sent and received."""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path
from typing import Callable, List, Tuple

import numpy as np
import pytest

import viscera
from conftest import SOURCE, Server, Session


def test_the_press_is_felt_and_pushes_back(session: Session) -> None:
    log = session.log
    assert log.commands > 5000, "a 1 kHz loop for 10 s sends thousands of commands"
    assert len(log.forces_z) > 1000, "the tip spent seconds in the tissue"
    # The organ pushes the tool out of it (up), and harder the deeper the tip is pressed.
    forces, depths = np.array(log.forces_z), np.array(log.depths)
    assert np.median(forces) > 0
    deep, shallow = forces[depths > 0.008], forces[(depths > 0.0) & (depths < 0.003)]
    assert len(deep) > 100 and len(shallow) > 100
    assert deep.mean() > 2 * shallow.mean() > 0
    assert session.round_trip.samples >= log.commands * 0.9
    assert 0 < session.round_trip.p50_us < 5000


def test_events_and_frames_arrive(session: Session) -> None:
    kinds = [e.kind for e in session.events]
    assert "instrument_claimed" in kinds and "contact_started" in kinds and "instrument_released" in kinds
    assert any(e.kind == "annotation" and e.text == "python: start of the press" for e in session.events)
    frame = session.frame
    assert frame is not None
    assert frame.positions.shape == (session.topology.vertex_count, 3)
    assert frame.positions.dtype == np.float32
    # A view of the received frame, not a copy, and read-only.
    assert not frame.positions.flags.owndata and not frame.positions.flags.writeable
    with pytest.raises(ValueError):
        frame.positions[0, 0] = 1.0
    assert session.topology.triangles.max() < session.topology.vertex_count


def test_requests_refused_with_the_servers_reason(server: Server, domain: int) -> None:
    c = viscera.session.Client(domain, 32)
    assert c.wait_for_scene(10.0) is not None
    claim = c.claim(77, 2.0)
    assert not claim and "77" in claim.why
    outcome = c.load_scene("no-such-scene", 10.0)
    assert outcome is not None and not outcome.accepted and "no-such-scene" in outcome.message
    bad = c.set_material(file_text='{"name": "half', file_name="half.json", timeout_s=10.0)
    assert bad is not None and not bad.accepted and "half.json" in bad.message
    with pytest.raises(viscera.UsageError, match="set_material"):
        c.set_material()
    with pytest.raises(viscera.UsageError, match="tip_m"):
        c.send_tip(1, [0.0, 0.0])
    assert c.pause(5.0)
    scene = c.scene()
    assert scene is not None and scene.paused
    assert c.resume(5.0)


def test_what_the_server_would_refuse_is_refused_at_once(server: Server, domain: int) -> None:
    # The participant: what every program's command line refuses (a 66,000-character station
    # crashed Cyclone; '*' reached live servers' partitions; 0 is no client id).
    for client_id, partition in ((0, ""), (33, "*"), (33, "s" * 66000), (33, "a/b")):
        with pytest.raises(viscera.UsageError):
            viscera.session.Client(domain, client_id, partition)
    # Requests the server's decoder refuses as malformed (it would never answer them: each call
    # waited its whole 30 s timeout): refused here at once, with the decoder's reason.
    c = viscera.session.Client(domain, 33)
    assert c.wait_for_scene(10.0) is not None
    started = time.monotonic()
    refused: List[Tuple[Callable[[], object], str]] = [
        (lambda: c.load_scene("../liver"), "scene_name"),
        (lambda: c.load_scene(""), "scene_name"),
        (lambda: c.load_scene(".hidden"), "scene_name"),
        (lambda: c.load_scene("liver\n"), "scene_name"),
        (lambda: c.set_material(youngs_modulus_pa=float("nan")), "youngs_modulus_pa"),
        (lambda: c.set_material(youngs_modulus_pa=-1.0), "youngs_modulus_pa"),
        (lambda: c.set_material(youngs_modulus_pa=1e-300), "youngs_modulus_pa"),
        (lambda: c.set_material(file_text="{}" + " " * 70000, file_name="big.json"), "file_text"),
        (lambda: c.set_material(file_text="{}", file_name="../../etc/passwd"), "file_name"),
        (lambda: c.set_physics_rate(0.0), "physics_rate_hz"),
    ]
    for call, reason in refused:
        with pytest.raises(viscera.UsageError, match=reason):
            call()
    assert time.monotonic() - started < 2.0, "a refusal waited for the server"
    with pytest.raises(ValueError, match="not finite"):
        c.send_tip(1, [0.0, float("nan"), 0.0])


def test_recording_reads_into_dataframes_as_the_official_reader_counts(session: Session) -> None:
    rec = viscera.recording.Recording(session.recording)
    official = json.loads(subprocess.run(["node", str(SOURCE / "tests/node/check_mcap.mjs"), str(session.recording)], check=True,
                                         capture_output=True, text=True).stdout)
    per_stream: dict[str, int] = {}
    for ch in official["channels"]:
        per_stream[ch["metadata"]["stream"]] = per_stream.get(ch["metadata"]["stream"], 0) + ch["streamCount"]
    frames = rec.dataframes()
    undecodable = rec.undecodable()
    for stream, count in per_stream.items():
        assert len(frames[stream]) + undecodable[stream] == count, stream
        assert undecodable[stream] == 0, stream
    forces = frames["force_feedback"]
    assert forces.index.name == "log_time" and forces.index.dtype == np.int64
    assert forces.index.is_monotonic_increasing
    assert {"force_x_n", "force_z_n", "penetration_m", "in_contact"} <= set(forces.columns)
    # What the client sent is what was recorded: every command of client 31, in order.
    commands = frames["instrument_command"]
    ours = commands[commands["client_id"] == session.client_id]
    assert len(ours) == session.log.commands
    assert (np.diff(ours["seq"].to_numpy().astype(np.int64)) == 1).all()
    # The forces it felt in contact are the recorded ones in contact (to the float).
    felt = forces[(forces["client_id"] == session.client_id) & forces["in_contact"]]
    assert len(felt) >= len(session.log.forces_z) * 0.9
    assert felt["force_z_n"].max() == pytest.approx(max(session.log.forces_z), rel=0.05)
    events = frames["event"]
    assert "python: start of the press" in list(events["text"])


def test_recording_frames_are_one_array(session: Session) -> None:
    rec = viscera.recording.Recording(session.recording)
    f = rec.frames()
    assert f.positions.ndim == 3 and f.positions.shape[1:] == (session.topology.vertex_count, 3)
    assert f.positions.shape[0] == len(f.log_time_ns) == len(f.frame) > 100  # 30+ frames a second for 10 s
    assert f.mismatched == 0
    np.testing.assert_array_equal(f.triangles, session.topology.triangles)
    # The press dents the surface: some vertex moves down by millimetres at the deepest point, and
    # the surface is back near rest before the press began (the first frames).
    dent = (f.rest_positions[None, :, 2] - f.positions[:, :, 2]).max(axis=1)
    assert 0.005 < dent.max() < 0.05
    assert dent[0] < 0.001
    assert rec.scene_file("scene").startswith(b"{")


def test_bad_recordings_raise_one_line(tmp_path: Path) -> None:
    with pytest.raises(viscera.InputError, match="nothing.mcap"):
        viscera.recording.Recording(tmp_path / "nothing.mcap")
    not_mcap = tmp_path / "notes.mcap"
    not_mcap.write_text("not a recording\n")
    with pytest.raises(viscera.InputError, match="notes.mcap") as e:
        viscera.recording.Recording(not_mcap)
    assert "\n" not in str(e.value)
