#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A recording into pandas DataFrames and numpy arrays with the Python package: the time every
stream and the frames take to read, the decoded size, and the peak resident memory of the process
against it. The issue's case is ten minutes of the 12k liver (bench/record.sh 600 with
KEEP=FILE). Writes bench/results/python_recording.json.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_recording.py RECORDING.mcap
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import resource
import time
import tracemalloc
from pathlib import Path

import viscera


def resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("recording")
    p.add_argument("--out", default=str(Path(__file__).resolve().parent / "results/python_recording.json"))
    a = p.parse_args()
    import pandas  # noqa: F401  (imported before the clock starts, as a notebook has it)

    base = resident_bytes()
    t0 = time.perf_counter()
    rec = viscera.recording.Recording(a.recording)
    frames_of_streams = rec.dataframes()
    t1 = time.perf_counter()
    frames = rec.frames()
    t2 = time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 - base
    decoded = sum(int(df.memory_usage(deep=True).sum()) for df in frames_of_streams.values()) + frames.positions.nbytes
    rows = {name: len(df) for name, df in frames_of_streams.items()}
    # Frame access copies nothing: taking one frame's positions allocates (numpy's allocations are
    # traced) far less than the frame's bytes.
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    one = frames.positions[len(frames.positions) // 2]
    allocated = tracemalloc.get_traced_memory()[0] - before
    tracemalloc.stop()
    cpu = re.search(r"model name\s*:\s*(.*)", open("/proc/cpuinfo").read())
    r = {
        "recording": a.recording,
        "file_bytes": os.path.getsize(a.recording),
        "rows": rows,
        "frames": list(frames.positions.shape),
        "read_s": t2 - t0,
        "streams_s": t1 - t0,
        "frames_s": t2 - t1,
        "decoded_bytes": decoded,
        "peak_resident_growth_bytes": peak,
        "peak_over_decoded": peak / decoded,
        "one_frame_bytes": one.nbytes,
        "one_frame_access_allocated_bytes": allocated,
        "machine": f"{cpu.group(1) if cpu else platform.processor()}, {os.cpu_count()} CPUs",
    }
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(r, indent=1) + "\n")
    print(f"{a.recording}: {r['file_bytes'] / 1e6:.0f} MB file; {sum(rows.values())} messages in {len(rows)} streams, "
          f"frames {tuple(frames.positions.shape)}")
    print(f"read into DataFrames and arrays in {r['read_s']:.2f} s (streams {r['streams_s']:.2f} s, frames {r['frames_s']:.2f} s; target 5 s)")
    print(f"decoded {decoded / 1e6:.0f} MB; peak resident growth {peak / 1e6:.0f} MB = {r['peak_over_decoded']:.2f}x (target under 2x)")
    print(f"one frame's positions: {one.nbytes} bytes, taking them allocated {allocated} bytes")
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
