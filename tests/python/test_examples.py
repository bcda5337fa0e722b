# SPDX-License-Identifier: Apache-2.0
"""The examples in examples/python run as a user runs them: the haptic client against the server,
the analysis of the session recorded by the session test, a quick lab fit of the titin data."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from conftest import SOURCE, Server, Session, program

EXAMPLES = SOURCE / "examples/python"


def run(*args: str) -> str:
    done = subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=300, env=os.environ.copy())
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_every_example_explains_itself() -> None:
    for example in ("haptic_client.py", "analyse_session.py", "lab_fit.py"):
        assert "usage:" in run(str(EXAMPLES / example), "--help")


def test_haptic_client_presses_and_reports(server: Server, domain: int) -> None:
    out = run(str(EXAMPLES / "haptic_client.py"), "--domain", str(domain), "--client-id", "61", "--duration", "3", "--depth", "0.01")
    assert "scene liver" in out and "round trip p50" in out
    peak = float(out.split("peak force ")[1].split(" N")[0])
    assert peak > 0.05, out


def test_the_readmes_first_clients_press_and_let_go(server: Server, domain: int) -> None:
    """The README's first clients, in C++ and in Python: the tip's centre starts 1 cm above the
    organ's bounds and is at least 6 mm above them in the first and last quarter second (the 3 mm
    tip touches nothing: no force), 2 cm below their top at the deepest (the tissue pushes it
    up)."""
    for command in ([program("examples/cpp/first_client"), str(domain)], [sys.executable, str(EXAMPLES / "first_client.py"), str(domain)]):
        done = subprocess.run(command, capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, f"{command[-2]}: {done.stderr}"
        forces = {float(x.split()[1]): float(x.split("force z ")[1].split()[0]) for x in done.stdout.splitlines()}
        above = [f for t, f in forces.items() if t <= 0.25 or t >= 3.75]
        deepest = [f for t, f in forces.items() if 1.75 <= t <= 2.25]
        assert len(forces) >= 15 and len(above) >= 3 and not any(above), f"{command[-2]}: {done.stdout}"
        assert deepest and min(deepest) > 0.05, f"{command[-2]}: no push at the deepest point: {done.stdout}"


def test_analyse_session_summarises_and_plots(session: Session, tmp_path: Path) -> None:
    png = tmp_path / "session.png"
    out = run(str(EXAMPLES / "analyse_session.py"), str(session.recording), "--plot", str(png))
    assert "instrument 1: peak force" in out and "tool path" in out and "note: python: start of the press" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    failed = subprocess.run([sys.executable, str(EXAMPLES / "analyse_session.py"), str(tmp_path / "none.mcap")], capture_output=True, text=True)
    assert failed.returncode == 2 and "none.mcap" in failed.stderr and failed.stderr.count("\n") == 1


def test_lab_fit_names_the_causes_and_plots(tmp_path: Path) -> None:
    png = tmp_path / "titin.png"
    out = run(str(EXAMPLES / "lab_fit.py"), str(SOURCE / "data/titin-passive-muscle"), "--quick", "--plot", str(png))
    assert "causes (confirmed)" in out and "honest gain" in out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
