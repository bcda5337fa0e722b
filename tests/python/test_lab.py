# SPDX-License-Identifier: Apache-2.0
"""The lab from Python gives viscera-lab's numbers: the same analysis of the bundled titin data,
compared figure by figure with the report.json the program writes."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any, List

import numpy as np
import pytest

import viscera
from conftest import SOURCE, program

TITIN = SOURCE / "data/titin-passive-muscle"


def figures_equal(a: Any, b: Any, path: str = "") -> None:
    """Every number of b equals a's to 1e-12 (relative), every string and flag the same."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), f"{path}: keys {sorted(set(a) ^ set(b))}"
        for k in a:
            if k != "seconds":
                figures_equal(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            figures_equal(x, y, f"{path}[{i}]")
    elif isinstance(a, float) or isinstance(b, float):
        assert b == pytest.approx(a, rel=1e-12, abs=1e-300), path
    else:
        assert a == b, path


def test_analyze_gives_the_programs_report(tmp_path: Path) -> None:
    subprocess.run([program("tools/viscera-lab/viscera-lab"), "analyze", str(TITIN), "--out", str(tmp_path / "cli"), "--quiet"], check=True,
                   capture_output=True)
    written = json.loads((tmp_path / "cli/report.json").read_text())
    lines: List[str] = []
    d = viscera.lab.read_dataset(TITIN)
    assert d.name.startswith("titin-passive-muscle") and len(d.tests) == 4 and d.contact == "bonded"
    # One specimen's tests in the listed order (the default history): each starts where the last left it.
    assert d.history == "carried" and d.tests[0].before_tension == 0.0
    assert d.tests[2].before_tension == pytest.approx(max(d.tests[0].strain.max(), d.tests[1].strain.max()), rel=1e-3)
    a = viscera.lab.analyze(d, progress=lines.append)
    assert len(lines) >= 3, "progress lines arrive while it runs"
    figures_equal(written, a.report)
    assert a.material_file == (tmp_path / "cli/material.json").read_text()
    assert a.baseline_material_file == (tmp_path / "cli/material-baseline.json").read_text()
    # The model, written and predicted by the program and by the package alike.
    a.write_model(tmp_path / "model.json")
    subprocess.run([program("tools/viscera-lab/viscera-lab"), "predict", str(tmp_path / "model.json"), str(TITIN), "--out", str(tmp_path / "p")],
                   check=True, capture_output=True)
    figures_equal(json.loads((tmp_path / "p/report.json").read_text()), viscera.lab.predict(tmp_path / "model.json", TITIN))
    # Never over the data set it was fitted to, nor through a link planted at the path.
    with pytest.raises(viscera.InputError, match="dataset.json"):
        a.write_model(TITIN / "dataset.json")
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    (tmp_path / "planted.json").symlink_to(victim)
    with pytest.raises(viscera.InputError, match="symbolic link"):
        a.write_model(tmp_path / "planted.json")
    assert victim.read_text() == "mine"
    # The prediction of a test is the model's: its RMS error is the report's.
    for t, reported in zip(a.dataset.tests, a.report["final"]["tests"]):
        y = a.predict(t.file, "final")
        assert y.shape == t.stress_pa.shape
        assert np.sqrt(np.mean((y - t.stress_pa) ** 2)) == pytest.approx(reported["fit_rms_pa"], rel=0.02)


def test_bad_data_sets_raise_one_line(tmp_path: Path) -> None:
    with pytest.raises(viscera.InputError, match="dataset.json") as e:
        viscera.lab.read_dataset(tmp_path)
    assert "\n" not in str(e.value)
    (tmp_path / "dataset.json").write_text('{"name": "x", "mode": "sideways"}')
    with pytest.raises(viscera.InputError, match="mode"):
        viscera.lab.read_dataset(tmp_path)
    d = viscera.lab.read_dataset(TITIN)
    with pytest.raises(viscera.UsageError, match="bootstrap"):
        viscera.lab.analyze(d, bootstrap_replicates=-1)
