# SPDX-License-Identifier: Apache-2.0
"""viscera-lab from Python: load a data set, analyze it, predict other data with the model.

    d = viscera.lab.read_dataset("data/titin-passive-muscle")
    a = viscera.lab.analyze(d, progress=print)
    a.report["causes"], a.report["nested_leave_one_out"]["gain"]
    a.plot("ramp_1s.csv")                    # matplotlib, where installed

``analyze`` is viscera-lab analyze (the same code, the same numbers: ``report`` is report.json as
the program writes it, parsed). It releases the interpreter lock while it runs.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Optional, Union

import numpy as np
import numpy.typing as npt

from ._viscera import lab as _lab
from ._viscera.lab import Dataset, Test

__all__ = ["Analysis", "Dataset", "Test", "analyze", "predict", "read_dataset"]

PathLike = Union[str, "os.PathLike[str]"]


class Analysis:
    """The result of analyze(): the report (report.json as a dict), the material files for the
    organ, and the models' predictions of each test."""

    def __init__(self, result: _lab.Analysis) -> None:
        self._a = result
        self.report: Dict[str, Any] = json.loads(result.report_json)

    @property
    def verdict(self) -> str:
        """One paragraph: what the baseline gets wrong, why, what still does not fit."""
        return str(self.report["verdict"])

    @property
    def causes(self) -> list[str]:
        """The mechanisms named as found (or tentative; see report["causes_status"])."""
        return list(self.report["causes"])

    @property
    def material_file(self) -> str:
        """material.json for a scene or viscera-control material --file ("" if not written; report["material_file"] says why)."""
        return self._a.material_file

    @property
    def baseline_material_file(self) -> str:
        """material-baseline.json: the linear baseline's material, to compare with."""
        return self._a.baseline_material_file

    @property
    def dataset(self) -> Dataset:
        """The data set as it was fitted (tests with many rows decimated)."""
        return self._a.dataset

    def predict(self, test: str, model: str = "supported") -> npt.NDArray[np.float64]:
        """A test's measured quantity as a model predicts it (stress [Pa] under strain control,
        strain under stress control), at the fitted data set's times. model: baseline, final, or
        supported (the model the analysis stands by)."""
        return self._a.predict(test, model)

    def write_model(self, path: PathLike) -> None:
        """Writes model.json (for predict() and viscera-lab predict)."""
        self._a.write_model(os.fspath(path))

    def plot(self, test: str, ax: Optional[Any] = None) -> Any:
        """Plots a test's data with the baseline's and the final model's predictions (matplotlib;
        ImportError if it is not installed). Returns the axes."""
        import matplotlib.pyplot as plt

        t = next((t for t in self.dataset.tests if t.file == test), None)
        if t is None:
            raise KeyError(f"{test!r} is not one of {', '.join(x.file for x in self.dataset.tests)}")
        if ax is None:
            _, ax = plt.subplots()
        measured = t.stress_pa if t.control == "strain" else t.strain
        unit = "stress [Pa]" if t.control == "strain" else "strain [-]"
        ax.plot(t.time_s, measured, ".", markersize=2, color="0.4", label="data")
        ax.plot(t.time_s, self.predict(test, "baseline"), "--", label="baseline")
        ax.plot(t.time_s, self.predict(test, "final"), "-", label="final")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(unit)
        ax.set_title(f"{self.report['dataset']}: {test}")
        ax.legend()
        return ax


def read_dataset(folder: PathLike) -> Dataset:
    """Reads DATASET_DIR/dataset.json and its CSVs (README, "The data a user brings"); raises
    viscera.InputError naming the file, line and field."""
    return _lab.read_dataset(os.fspath(folder))


def _dataset(d: Union[Dataset, PathLike]) -> Dataset:
    return d if isinstance(d, Dataset) else read_dataset(os.fspath(d))


def analyze(
    dataset: Union[Dataset, PathLike],
    *,
    specimen: bool = True,
    nested: bool = True,
    bootstrap_replicates: int = 40,
    max_fit_points: int = 2000,
    progress: Optional[Callable[[str], None]] = None,
) -> Analysis:
    """viscera-lab analyze on a data set (or its folder): fits the linear baseline, shows where it
    is wrong on held-out tests, names the cause, extends the model and measures the gain.
    specimen: also run baseline and final on the meshed specimen; nested: the nested leave-one-out
    (the honest gain); bootstrap_replicates: draws for the parameters' uncertainties; progress:
    called with one line per stage."""
    return Analysis(
        _lab.analyze(
            _dataset(dataset),
            specimen=specimen,
            nested=nested,
            bootstrap_replicates=bootstrap_replicates,
            max_fit_points=max_fit_points,
            progress=progress,
        )
    )


def predict(model: PathLike, dataset: Union[Dataset, PathLike]) -> Dict[str, Any]:
    """viscera-lab predict: per-test RMS errors [Pa] of a model.json on a data set (report.json as a dict)."""
    result: Dict[str, Any] = json.loads(_lab.predict(os.fspath(model), _dataset(dataset)))
    return result
