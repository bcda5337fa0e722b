#!/usr/bin/env bash
# Haptic loop over DDS in one run: ddsperf ping-pong (the floor) and viscera-server + haptic-client
# at 1 kHz on the liver at 1.5k and 12k tetrahedra. Prints a markdown table (docs/PERFORMANCE.md).
# Usage: [DEPTH=0.02] bench/haptics.sh [SECONDS]   (default 30 s; DEPTH: press depth in metres)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-30}"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/cyclonedds.xml"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
ddsperf -D "$((seconds + 2))" pong >/dev/null 2>&1 &
sleep 0.5
ddsperf -D "$seconds" ping 1000Hz size 64 > "$tmp/ping.log" 2>&1 || true
wait || true
python3 - "$tmp/ping.log" > "$tmp/ping.txt" <<'PY'
import re, statistics, sys
p50, p99, mx = [], [], []
for line in open(sys.argv[1]):
    m = re.search(r"50% ([0-9.]+)us 90% [0-9.]+us 99% ([0-9.]+)us max ([0-9.]+)us", line)
    if m:
        p50.append(float(m.group(1))); p99.append(float(m.group(2))); mx.append(float(m.group(3)))
print(f"| ddsperf ping-pong, 64 B at 1 kHz (as ddsperf prints it) | {statistics.median(p50):.0f} | {statistics.median(p99):.0f} | {max(mx):.0f} | - | - | - | - | - |")
PY
for scene in liver liver-12k; do
  domain=$(( (RANDOM % 200) + 1 ))
  sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
    "$root/data/scenes/$scene.json" > "$tmp/$scene.json"
  "$root/build/server/runtime/viscera-server" --scene "$tmp/$scene.json" --duration "$((seconds + 4))" > "$tmp/$scene.server.log" 2>&1 &
  server=$!
  "$root/build/tools/haptic-client/haptic-client" --domain "$domain" --duration "$seconds" --depth "${DEPTH:-0.02}" --report "$tmp/$scene.json.report" > /dev/null
  wait "$server"
  python3 - "$scene" "$tmp/$scene.json.report" "$tmp/$scene.server.log" >> "$tmp/ping.txt" <<'PY'
import json, re, statistics, sys
scene, report, log = sys.argv[1:]
r = json.load(open(report))["round_trip_us"]
p50, p99, mx, jit, rate = [], [], [], [], []
tets = ""
overruns = 0
resets = 0
for line in open(log):
    m = re.search(r"([0-9]+) Hz physics, step p50 ([0-9]+) us p99 ([0-9]+) us max ([0-9]+) us, jitter p99 ([0-9]+) us, overruns ([0-9]+)", line)
    if m:
        rate.append(float(m.group(1))); p50.append(float(m.group(2))); p99.append(float(m.group(3))); mx.append(float(m.group(4)))
        jit.append(float(m.group(5))); overruns = int(m.group(6))
    m = re.search(r"([0-9]+) tets", line)
    if m: tets = m.group(1)
    m = re.search(r"([0-9]+) physics resets", line)
    if m: resets = int(m.group(1))
print(f"| viscera {scene} ({tets} tets): pose -> force round trip | {r['p50']:.0f} | {r['p99']:.0f} | {r['max']:.0f} | "
      f"{statistics.median(rate):.0f} | {statistics.median(p50):.0f} / {max(p99):.0f} | {max(jit):.0f} | {overruns} | {resets} |")
PY
done
echo "| measurement | p50 [us] | p99 [us] | max [us] | physics rate [Hz] | step p50 / worst p99 [us] | tick jitter p99 [us] | overruns | physics resets |"
echo "|---|---|---|---|---|---|---|---|---|"
cat "$tmp/ping.txt"
