#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A scripted haptic client in Python: claims a probe, presses the organ from above at the centre of
its bounds at a fixed rate (default 1 kHz), down to a depth below the surface and back, and
prints the forces, the command-to-force round trip and the periods that ran late.

    PYTHONPATH=build/python python3 examples/python/haptic_client.py --domain 0 --duration 10

With a viscera-server running (./deploy/run.sh starts one on domain 0).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import viscera


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--domain", type=int, default=0, help="DDS domain id of the server")
    p.add_argument("--client-id", type=int, default=7001, help="this client's id (one process per id)")
    p.add_argument("--instrument", type=int, default=1, help="the probe to claim")
    p.add_argument("--duration", type=float, default=10.0, help="[s] length of the press")
    p.add_argument("--depth", type=float, default=0.01, help="[m] deepest point below the surface")
    p.add_argument("--rate", type=float, default=1000.0, help="[Hz] commands per second")
    p.add_argument("--late-ms", type=float, default=2.0, help="[ms] a period longer than this counts as late")
    p.add_argument("--report", metavar="JSON", help="write the round trip, the periods and their start times [s] here")
    a = p.parse_args()

    client = viscera.session.Client(a.domain, a.client_id)
    scene = client.wait_for_scene(10.0)
    if scene is None:
        print(f"haptic_client.py: no viscera-server on DDS domain {a.domain} within 10 s", file=sys.stderr)
        return 1
    claim = client.claim(a.instrument, 3.0)
    if not claim:
        print(f"haptic_client.py: instrument {a.instrument} not claimed: {claim.why}", file=sys.stderr)
        return 1
    surface = None
    while surface is None:
        surface = client.surface()
        time.sleep(0.01)
    # The surface under the centre of the organ's bounds: the highest rest vertex within 1 cm.
    cx = 0.5 * (scene.bounds_min_m[0] + scene.bounds_max_m[0])
    cy = 0.5 * (scene.bounds_min_m[1] + scene.bounds_max_m[1])
    rest = surface.rest_positions
    near = rest[(rest[:, 0] - cx) ** 2 + (rest[:, 1] - cy) ** 2 < 0.01**2]
    top = (cx, cy, float(near[:, 2].max()) if len(near) else scene.bounds_max_m[2])
    radius = next((i.tip_radius_m for i in scene.instruments if i.instrument_id == a.instrument), 0.0)
    above = radius + 0.003  # the tip starts 3 mm above the surface

    # The loop as the C++ device loop runs it: each command waits for its answer until shortly
    # before the next period, and the periods keep a fixed phase after the server's ticks
    # (TickPhase, 100 us after a tick's end) when the loop runs at the physics rate.
    period = 1.0 / a.rate
    phase = viscera.session.TickPhase(period, 100e-6) if abs(scene.physics_rate_hz - a.rate) <= 0.01 * a.rate else None
    start = time.monotonic()
    last = start
    next_t = start
    periods = late = 0
    worst = 0.0
    peak = 0.0
    starts: list[float] = []
    while (now := time.monotonic()) - start < a.duration:
        if a.report:
            starts.append(now - start)
        progress = (now - start) / a.duration
        depth = (a.depth + above) * (1 - abs(2 * progress - 1)) - above  # of the tip's lowest point below the surface
        client.send_tip(a.instrument, [top[0], top[1], top[2] + radius - depth])
        force = client.wait_force(a.instrument, max(0.0, next_t + period - 100e-6 - time.monotonic()))
        if force is not None:
            peak = max(peak, force.force_n[2])
        periods += 1
        gap = now - last
        last = now
        if periods > 1:
            worst = max(worst, gap)
            late += gap > a.late_ms * 1e-3
        next_t += period
        tick_end = client.last_tick_end_ns(a.instrument) if phase is not None else None
        if phase is not None and tick_end is not None:
            next_ns = viscera.session.now_ns() + int((next_t - time.monotonic()) * 1e9)
            next_t += phase.correction_ns(next_ns, tick_end) * 1e-9
        pause = next_t - time.monotonic()
        if pause > 0:
            time.sleep(pause)
    client.release(a.instrument)
    rt = client.round_trip()
    print(f"scene {scene.name}: {periods} periods in {a.duration:g} s ({periods / a.duration:.0f} Hz), peak force {peak:.3f} N")
    print(f"round trip p50 {rt.p50_us:.0f} us, p99 {rt.p99_us:.0f} us, max {rt.max_us:.0f} us over {rt.samples} forces")
    print(f"periods over {a.late_ms:g} ms: {late} ({100.0 * late / max(periods, 1):.3f}%), longest {worst * 1e3:.2f} ms")
    if a.report:
        report = {"rate_hz": a.rate, "duration_s": a.duration, "periods": periods, "late_periods": late, "late_ms": a.late_ms,
                  "longest_period_ms": worst * 1e3, "peak_force_z_n": peak,
                  "round_trip_us": {"samples": rt.samples, "p50": rt.p50_us, "p99": rt.p99_us, "max": rt.max_us}, "period_starts_s": starts}
        with open(a.report, "w") as f:
            json.dump(report, f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
