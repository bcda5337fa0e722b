#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A recorded training session, analysed: the force on each instrument, the tool's path, the
tissue's largest edge strain over time, and the surface's deepest dent; printed, and plotted to
a PNG when matplotlib is installed.

    PYTHONPATH=build/python python3 examples/python/analyse_session.py session.mcap --plot session.png
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import viscera


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("recording", help="an MCAP recording written by viscera-record")
    p.add_argument("--plot", metavar="PNG", help="write the plots to this file")
    a = p.parse_args()
    try:
        rec = viscera.recording.Recording(a.recording)
    except viscera.InputError as e:
        print(f"analyse_session.py: {e}", file=sys.stderr)
        return 2
    forces = rec.dataframe("force_feedback")
    commands = rec.dataframe("instrument_command")
    t0 = rec.start_ns
    lost = rec.drops.get("missing", "?") if rec.drops is not None else "unknown (a recovered recording)"
    print(f"{a.recording}: {(rec.end_ns - t0) / 1e9:.1f} s, {len(commands)} commands, {len(forces)} forces, samples lost by the recorder: {lost}")
    for instrument, f in forces.groupby("instrument_id"):
        magnitude = np.sqrt(f["force_x_n"] ** 2 + f["force_y_n"] ** 2 + f["force_z_n"] ** 2)
        contact = f["in_contact"].mean()
        print(f"instrument {instrument}: peak force {magnitude.max():.3f} N, in contact {100 * contact:.1f}% of forces, "
              f"deepest {1e3 * f['penetration_m'].max():.1f} mm, largest edge strain {f['max_edge_strain'].max():.3f}")
    for instrument, c in commands.groupby("instrument_id"):
        path = np.sqrt(np.diff(c["tip_x_m"]) ** 2 + np.diff(c["tip_y_m"]) ** 2 + np.diff(c["tip_z_m"]) ** 2).sum()
        print(f"instrument {instrument}: tool path {100 * path:.1f} cm")
    frames = None
    if rec.mesh_ids():
        frames = rec.frames()
        dent = (frames.rest_positions[None, :, 2] - frames.positions[:, :, 2]).max(axis=1)
        print(f"surface: {frames.positions.shape[0]} frames of {frames.positions.shape[1]} vertices, deepest dent {1e3 * dent.max():.1f} mm")
    events = rec.dataframe("event")
    for when, event in events.iterrows():
        if event["kind"] == "annotation":
            print(f"  {(int(str(when)) - t0) / 1e9:7.2f} s  note: {event['text']}")
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
        for instrument, f in forces.groupby("instrument_id"):
            ax[0].plot((f.index - t0) / 1e9, f["force_z_n"], label=f"instrument {instrument}")
            ax[2].plot((f.index - t0) / 1e9, f["max_edge_strain"])
        for instrument, c in commands.groupby("instrument_id"):
            ax[1].plot((c.index - t0) / 1e9, 1e3 * c["tip_z_m"])
        ax[0].set_ylabel("force z [N]")
        ax[0].legend()
        ax[1].set_ylabel("tip z [mm]")
        ax[2].set_ylabel("largest edge strain [-]")
        ax[2].set_xlabel("time [s]")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=100)
        print(f"wrote {a.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
