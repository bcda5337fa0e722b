# SPDX-License-Identifier: Apache-2.0
"""Session recordings (MCAP, written by viscera-record) as pandas DataFrames and numpy arrays.

    rec = viscera.recording.Recording("session.mcap")
    forces = rec.dataframe("force_feedback")      # one row per message, index log_time [ns]
    frames = rec.frames()                         # the organ's surface, (n_frames, n_vertices, 3)

The file is read by viscera's own reader (the replayer's): checked to be a complete viscera
recording, each message decoded and verified by the protocol's decoders; messages that do not
decode are counted (``undecodable``), never guessed at. Column names carry their units
(``force_x_n``, ``tip_x_m``, ``step_p99_us``); flags are booleans; names of kinds and actions are
strings. All streams are read in one pass, the first time any is asked for.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Union

import numpy as np
import numpy.typing as npt

from ._viscera.recording import Recording as _Recording
from ._viscera.recording import tabulated_streams

__all__ = ["Recording", "Frames", "tabulated_streams"]


@dataclass(frozen=True)
class Frames:
    """The surface frames of one organ mesh (one scene's SurfaceTopology).

    positions: (n_frames, n_vertices, 3) float32 [m]; log_time_ns, frame, tick, sim_time_s: one per
    frame; triangles: (n_triangles, 3) vertex indices; rest_positions: (n_vertices, 3) float32 [m]
    (both empty if the topology was not recorded); mismatched: frames dropped for another vertex
    count. A scalpel's cut changes the surface (docs/CUTTING.md): the frames are those of one
    topology_generation, the first recorded; later_generation_frames counts the frames left out
    (of a cut surface) and last_topology_generation is the newest seen. Arrays are read-only and
    own their memory.
    """

    mesh_id: int
    positions: npt.NDArray[np.float32]
    log_time_ns: npt.NDArray[np.int64]
    frame: npt.NDArray[np.uint64]
    tick: npt.NDArray[np.uint64]
    sim_time_s: npt.NDArray[np.float64]
    triangles: npt.NDArray[np.uint32]
    rest_positions: npt.NDArray[np.float32]
    mismatched: int
    topology_generation: int = 0
    later_generation_frames: int = 0
    last_topology_generation: int = 0


class Recording:
    """A session recording opened for reading. Raises viscera.InputError naming the file when it
    is not MCAP, is damaged, was cut short (``viscera-record recover`` it first), is not a viscera
    recording, or was made by a newer schema."""

    def __init__(self, path: Union[str, "os.PathLike[str]"]) -> None:
        self._r = _Recording(os.fspath(path))
        self._tables: Optional[Dict[str, Any]] = None
        self._frames: Dict[int, Frames] = {}
        self._frames_read = False

    @property
    def path(self) -> str:
        """The recording's file."""
        return self._r.path

    @property
    def info(self) -> Dict[str, str]:
        """Metadata viscera.recording: schema_version, domain_id, partition, streams, recorder."""
        return self._r.info

    @property
    def drops(self) -> Optional[Dict[str, str]]:
        """Samples the recorder lost, per stream (None for a recording recovered after a crash)."""
        return self._r.drops

    @property
    def message_counts(self) -> Dict[str, int]:
        """Messages per stream, as the recording's summary counts them."""
        return self._r.message_counts

    @property
    def start_ns(self) -> int:
        """[ns] log time of the first message."""
        return self._r.start_ns

    @property
    def end_ns(self) -> int:
        """[ns] log time of the last message."""
        return self._r.end_ns

    @property
    def scenes(self) -> List[Dict[str, Any]]:
        """The scenes the server ran: generation, first_tick, sim_time_s [s], log_time_ns, settings_json,
        server_version and files (role, path, attachment, sha256)."""
        return self._r.scenes

    def scene_file(self, role: str = "scene", generation: Optional[int] = None) -> bytes:
        """The content of a file a scene was built from (role: scene, mesh, material,
        region.K.material), of the scene of that generation (None: the last)."""
        scenes = self.scenes
        chosen = [s for s in scenes if generation is None or s["generation"] == generation]
        if not chosen:
            raise KeyError(f"{self.path}: no scene of generation {generation}")
        for f in chosen[-1]["files"]:
            if f["role"] == role:
                return self._r.attachment(f["attachment"])
        raise KeyError(f"{self.path}: the scene has no file of role {role!r}")

    def _read(self) -> Dict[str, Any]:
        if self._tables is None:
            raw = self._r.read(set(), True)
            self._tables = raw["streams"]
            for mesh_id, f in raw["frames"].items():
                self._frames[int(mesh_id)] = Frames(
                    mesh_id=int(mesh_id),
                    positions=f["positions"],
                    log_time_ns=f["log_time_ns"],
                    frame=f["frame"],
                    tick=f["tick"],
                    sim_time_s=f["sim_time_s"],
                    triangles=f["triangles"],
                    rest_positions=f["rest_positions"],
                    mismatched=int(f["mismatched"]),
                    topology_generation=int(f["topology_generation"]),
                    later_generation_frames=int(f["later_generation_frames"]),
                    last_topology_generation=int(f["last_topology_generation"]),
                )
        return self._tables

    def undecodable(self) -> Dict[str, int]:
        """Messages per stream that did not decode (and are in no DataFrame)."""
        return {name: int(t["undecodable"]) for name, t in self._read().items()}

    def columns(self, stream: str) -> Dict[str, Any]:
        """A stream's columns as numpy arrays (strings as lists), with "log_time_ns"; no pandas needed."""
        tables = self._read()
        if stream not in tables:
            raise KeyError(f"{self.path}: stream {stream!r} is not one of {', '.join(sorted(tables))}")
        t = tables[stream]
        return {"log_time_ns": t["log_time_ns"], **t["columns"]}

    def dataframe(self, stream: str) -> "Any":
        """A stream as a pandas DataFrame: one row per message, in log-time order, indexed by an
        int64 ``log_time`` [ns]; source_id, writer and sequence (the envelope's) then the message's
        fields, named with their units."""
        import pandas as pd

        cols = self.columns(stream)
        index = pd.Index(cols.pop("log_time_ns"), name="log_time")
        return pd.DataFrame(cols, index=index, copy=False)

    def dataframes(self) -> Dict[str, "Any"]:
        """Every tabulated stream as a DataFrame (see dataframe)."""
        return {name: self.dataframe(name) for name in self._read()}

    def frames(self, mesh_id: Optional[int] = None) -> Frames:
        """The surface frames of one organ mesh (None: the only one, or the last when a scene was
        loaded during the session)."""
        self._read()
        if not self._frames:
            raise KeyError(f"{self.path}: the recording has no surface frames")
        if mesh_id is None:
            mesh_id = max(self._frames)
        if mesh_id not in self._frames:
            raise KeyError(f"{self.path}: no frames of mesh {mesh_id} (there are {sorted(self._frames)})")
        return self._frames[mesh_id]

    def mesh_ids(self) -> List[int]:
        """The organ meshes that have frames or a topology in the recording."""
        self._read()
        return sorted(self._frames)
