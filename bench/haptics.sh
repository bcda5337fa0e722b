#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Haptic loop over DDS in one run: ddsperf ping-pong (the floor), then viscera-server + haptic-client
# at 1 kHz on the liver at 1.5k, 12k (and with SCENES="... liver-96k" 96k) tetrahedra, each scene
# twice: without mesh updates, and with surface frames at 60 Hz received by the haptic client.
# REPEAT=N runs every pair N times, interleaved (the run-to-run spread on a shared machine is
# larger than the effect of the mesh updates), and reports the median ratio.
# Prints a markdown table and writes bench/results/haptics.json (docs/PERFORMANCE.md's tables are
# generated from it by bench/performance_tables.py).
# CLIENT_ARGS adds haptic-client options (e.g. CLIENT_ARGS="--tick-phase -1": a free-running device loop).
# Usage: [DEPTH=0.02] [SCENES="liver liver-12k"] [REPEAT=1] [CLIENT_ARGS=...] bench/haptics.sh [SECONDS]   (default 30 s)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-30}"
mkdir -p "$root/bench/results"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
ddsperf -D "$((seconds + 2))" pong >/dev/null 2>&1 &
sleep 0.5
ddsperf -D "$seconds" ping 1000Hz size 64 > "$tmp/ping.log" 2>&1 || true
wait || true
python3 - "$tmp/ping.log" "$tmp/rows.jsonl" > "$tmp/rows.txt" <<'PY'
import json, re, statistics, sys
p50, p99, mx = [], [], []
for line in open(sys.argv[1]):
    m = re.search(r"50% ([0-9.]+)us 90% [0-9.]+us 99% ([0-9.]+)us max ([0-9.]+)us", line)
    if m:
        p50.append(float(m.group(1))); p99.append(float(m.group(2))); mx.append(float(m.group(3)))
print(f"| ddsperf ping-pong, 64 B at 1 kHz (as ddsperf prints it) | - | {statistics.median(p50):.0f} | {statistics.median(p99):.0f} | {max(mx):.0f} | - | - | - | - | - | - | - |")
with open(sys.argv[2], "a") as f:
    f.write(json.dumps({"kind": "ddsperf", "p50_us": statistics.median(p50), "p99_us": statistics.median(p99), "max_us": max(mx)}) + "\n")
PY
for rep in $(seq "${REPEAT:-1}"); do
for scene in ${SCENES:-liver liver-12k}; do
  for mesh_hz in 0 60; do
    domain=$(( (RANDOM % 200) + 1 ))
    sed "s/\"domain_id\": 0/\"domain_id\": $domain, \"mesh_rate_hz\": $mesh_hz/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
      "$root/data/scenes/$scene.json" > "$tmp/$scene.json"
    "$root/build/server/runtime/viscera-server" --scene "$tmp/$scene.json" > "$tmp/server.log" 2>&1 &
    server=$!
    watch=""; [ "$mesh_hz" -gt 0 ] && watch="--watch-mesh"
    # The client waits for the server (large meshes take seconds to load), then runs SECONDS.
    "$root/build/tools/haptic-client/haptic-client" --domain "$domain" --duration "$seconds" --depth "${DEPTH:-0.02}" $watch \
      --report "$tmp/report.json" ${CLIENT_ARGS:-} > /dev/null
    kill -INT "$server"; wait "$server"
    python3 - "$scene" "$mesh_hz" "$tmp/report.json" "$tmp/server.log" "$tmp/rows.jsonl" >> "$tmp/rows.txt" <<'PY'
import json, re, statistics, sys
scene, mesh_hz, report, log, jsonl = sys.argv[1:]
rep = json.load(open(report))
r = rep["round_trip_us"]
# The client's device loop: samples rendered per second from the local force model.
s = rep["samples"]
render_hz = (len(s) - 1) / (s[-1]["t_s"] - s[0]["t_s"]) if len(s) > 1 else 0
frames = f"{rep['mesh']['rate_hz']:.0f}" if "mesh" in rep else "-"
p50, p99, mx, jit, rate = [], [], [], [], []
tets = ""
late = missed = resets = 0
for line in open(log):
    m = re.search(r"([0-9]+) Hz physics, step p50 ([0-9]+) us p99 ([0-9]+) us max ([0-9]+) us, jitter p99 ([0-9]+) us, late ticks ([0-9]+), missed slots ([0-9]+)", line)
    if m:
        rate.append(float(m.group(1))); p50.append(float(m.group(2))); p99.append(float(m.group(3))); mx.append(float(m.group(4)))
        jit.append(float(m.group(5))); late = int(m.group(6)); missed = int(m.group(7))
    m = re.search(r"([0-9]+) tets", line)
    if m: tets = m.group(1)
    m = re.search(r"([0-9]+) physics resets", line)
    if m: resets = int(m.group(1))
print(f"| viscera {scene} ({tets} tets): pose -> force round trip | {frames} | {r['p50']:.0f} | {r['p99']:.0f} | {r['max']:.0f} | "
      f"{statistics.median(rate):.0f} | {statistics.median(p50):.0f} / {max(p99):.0f} | {max(jit):.0f} | {late} | {missed} | {resets} | {render_hz:.0f} |")
with open(jsonl, "a") as f:
    f.write(json.dumps({"kind": "viscera", "scene": scene, "tets": int(tets or 0), "mesh_hz": int(mesh_hz), "frames_hz": rep["mesh"]["rate_hz"] if "mesh" in rep else 0,
                        "p50_us": r["p50"], "p99_us": r["p99"], "max_us": r["max"], "rate_hz": statistics.median(rate), "step_p50_us": statistics.median(p50),
                        "step_p99_us": max(p99), "jitter_p99_us": max(jit), "late_ticks": late, "missed_slots": missed, "physics_resets": resets,
                        "render_hz": render_hz, "seconds": rep["duration_s"]}) + "\n")
PY
  done
done
done
echo "| measurement | mesh frames received [Hz] | p50 [us] | p99 [us] | max [us] | physics rate [Hz] | step p50 / worst p99 [us] | tick jitter p99 [us] | late ticks | missed slots | physics resets | client force rendering [Hz] |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
cat "$tmp/rows.txt"
python3 - "$tmp/rows.jsonl" "$root/bench/results/haptics.json" <<'PY'
import json, os, platform, statistics, sys, time
rows = [json.loads(l) for l in open(sys.argv[1])]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.machine())
json.dump({"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "machine": f"{cpu}, {os.cpu_count()} CPUs", "rows": rows},
          open(sys.argv[2], "w"), indent=1)
PY
python3 - "$tmp/rows.txt" <<'PY'
import statistics, sys
rows = [l.split("|") for l in open(sys.argv[1]) if l.startswith("| viscera")]
ratios = {}
for off, on in zip(rows[0::2], rows[1::2]):
    name = off[1].split(":")[0].strip()
    ratios.setdefault(name, []).append((float(on[4]) / float(off[4]), float(on[3]) / float(off[3])))
print()
for name, r in ratios.items():
    p99 = [a for a, _ in r]; p50 = [b for _, b in r]
    print(f"- {name}: round-trip p99 with 60 Hz mesh updates / without = {statistics.median(p99):.2f} (median of {len(r)}: "
          + ", ".join(f"{a:.2f}" for a in p99) + f"), p50 {statistics.median(p50):.2f}")
PY
python3 "$root/bench/performance_tables.py" "$root"
