#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The soak's summary (bench/soak.sh): growth per hour of the server's resident memory, threads and
file descriptors, fitted by least squares over the samples after the warm-up; soak.json and a plot,
soak.svg. Usage: soak_report.py SAMPLES.csv OUT_DIR WARMUP_S MINUTES SCENE ALIVE RC_SERVER
"PRESS_RUNS PRESS_FAILED" "GRASP_RUNS GRASP_FAILED" "REQUESTS REQUESTS_FAILED"
Exit status 1 if the server died or exited non-zero, or a client run or request failed."""
import csv
import json
import os
import platform
import sys
import time


def fit(ts, ys):
    """Slope and intercept of the least-squares line."""
    n = len(ts)
    if n < 2:
        return 0.0, ys[0] if ys else 0.0
    mt, my = sum(ts) / n, sum(ys) / n
    var = sum((t - mt) ** 2 for t in ts)
    slope = sum((t - mt) * (y - my) for t, y in zip(ts, ys)) / var if var > 0 else 0.0
    return slope, my - slope * mt


def noise(ts, ys, slope, icpt):
    """RMS of the residuals about the fitted line."""
    r = [y - (slope * t + icpt) for t, y in zip(ts, ys)]
    return (sum(x * x for x in r) / max(len(r), 1)) ** 0.5


def panel(x0, y0, w, h, ts, ys, title, unit, fitted):
    lo, hi = min(ys), max(ys)
    if hi - lo < 1e-9:
        lo, hi = lo - 1, hi + 1
    pad = 0.1 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    tmax = max(ts) if ts and max(ts) > 0 else 1
    sx = lambda t: x0 + w * t / tmax
    sy = lambda y: y0 + h - h * (y - lo) / (hi - lo)
    out = [f'<rect x="{x0}" y="{y0}" width="{w}" height="{h}" fill="none" stroke="#888"/>',
           f'<text x="{x0}" y="{y0 - 6}" font-size="13">{title} [{unit}]</text>',
           f'<text x="{x0 - 6}" y="{y0 + 4}" font-size="11" text-anchor="end">{hi:.4g}</text>',
           f'<text x="{x0 - 6}" y="{y0 + h}" font-size="11" text-anchor="end">{lo:.4g}</text>',
           f'<text x="{x0 + w}" y="{y0 + h + 15}" font-size="11" text-anchor="end">{tmax / 60:.0f} min</text>']
    pts = " ".join(f"{sx(t):.1f},{sy(y):.1f}" for t, y in zip(ts, ys))
    out.append(f'<polyline points="{pts}" fill="none" stroke="#1f77b4" stroke-width="1.5"/>')
    if fitted:
        slope, icpt, t0 = fitted
        out.append(f'<line x1="{sx(t0):.1f}" y1="{sy(slope * t0 + icpt):.1f}" x2="{sx(tmax):.1f}" y2="{sy(slope * tmax + icpt):.1f}" '
                   f'stroke="#d62728" stroke-dasharray="5,3"/>')
    return out


def main():
    if len(sys.argv) != 11:
        print(__doc__, file=sys.stderr)
        return 2
    samples, out_dir, warmup, minutes, scene, alive, rc_server = sys.argv[1:8]
    counts = [tuple(int(x) for x in (c.split() or ["0", "0"])) for c in sys.argv[8:11]]
    rows = [r for r in csv.DictReader(open(samples))]
    ts = [float(r["t_s"]) for r in rows]
    warm = float(warmup)
    keep = [i for i, t in enumerate(ts) if t >= warm] or list(range(len(ts)))
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.machine())
    result = {"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "machine": f"{cpu}, {os.cpu_count()} CPUs",
              "minutes": float(minutes), "scene": os.path.basename(scene), "samples": len(rows), "warmup_s": warm,
              "server_alive_throughout": alive == "1", "server_exit_status": int(rc_server),
              "press_runs": counts[0][0], "press_failed": counts[0][1], "grasp_runs": counts[1][0], "grasp_failed": counts[1][1],
              "console_requests": counts[2][0], "console_failed": counts[2][1], "series": {}}
    svg = ['<svg xmlns="http://www.w3.org/2000/svg" width="900" height="330" font-family="sans-serif">',
           f'<text x="20" y="20" font-size="14">viscera-server soak: {result["scene"]}, {float(minutes):g} min, '
           f'{counts[0][0]} press runs, {counts[1][0]} grasp runs, {counts[2][0]} console requests (dashed: fit after the warm-up)</text>']
    for k, (key, title, unit, scale) in enumerate([("rss_kb", "resident memory", "MB", 1 / 1024), ("threads", "threads", "", 1), ("fds", "file descriptors", "", 1)]):
        ys = [float(r[key]) * scale for r in rows]
        kt, ky = [ts[i] for i in keep], [ys[i] for i in keep]
        slope, icpt = fit(kt, ky)
        result["series"][key] = {"unit": unit or "count", "first": ys[0] if ys else None, "last": ys[-1] if ys else None,
                                 "min": min(ys) if ys else None, "max": max(ys) if ys else None,
                                 "growth_per_hour": slope * 3600, "noise_rms": noise(kt, ky, slope, icpt)}
        svg += panel(60 + 290 * k, 50, 230, 240, ts, ys, title, unit or "count", (slope, icpt, kt[0]) if kt else None)
    svg.append("</svg>")
    with open(os.path.join(out_dir, "soak.json"), "w") as f:
        json.dump(result, f, indent=1)
    with open(os.path.join(out_dir, "soak.svg"), "w") as f:
        f.write("\n".join(svg) + "\n")
    s = result["series"]
    print(f"soak: {float(minutes):g} min on {result['scene']}: resident memory {s['rss_kb']['first']:.1f} -> {s['rss_kb']['last']:.1f} MB "
          f"(growth {s['rss_kb']['growth_per_hour']:+.2f} MB/h after the warm-up, noise {s['rss_kb']['noise_rms']:.2f} MB), "
          f"threads {s['threads']['first']:.0f} -> {s['threads']['last']:.0f} ({s['threads']['growth_per_hour']:+.2f}/h), "
          f"fds {s['fds']['first']:.0f} -> {s['fds']['last']:.0f} ({s['fds']['growth_per_hour']:+.2f}/h)")
    print(f"soak: press runs {counts[0][0]} ({counts[0][1]} failed), grasp runs {counts[1][0]} ({counts[1][1]} failed), "
          f"console requests {counts[2][0]} ({counts[2][1]} failed); server {'alive throughout' if alive == '1' else 'DIED'}, exit status {rc_server}")
    print(f"soak: wrote {out_dir}/soak.json and {out_dir}/soak.svg")
    ok = alive == "1" and rc_server == "0" and all(c[1] == 0 for c in counts)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
