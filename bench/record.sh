#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The recorder under the load the issue names: viscera-server on a scene (default the 12k liver,
# surface frames at 60 Hz), a haptic client pressing at 1 kHz for SECONDS (default 600: ten
# minutes), viscera-record recording every stream on loopback. Measures the file's size, the
# recorder's CPU time and peak memory, and what was lost: each writer's missing sequence numbers
# (the recorder's own count) and, independently, the forces and frames the server says it
# published against those in the file. Writes bench/results/record.json (docs/PERFORMANCE.md's
# table comes from it through bench/performance_tables.py) and prints a summary.
# KEEP=FILE keeps the recording there (bench/python_recording.py reads it into DataFrames).
# Usage: [SCENE=liver-12k] [COMPRESSION=zstd] [KEEP=FILE] bench/record.sh [SECONDS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-600}"
scene_name="${SCENE:-liver-12k}"
mkdir -p "$root/bench/results"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
domain=$(( (RANDOM % 200) + 1 ))
sed "s/\"domain_id\": 0/\"domain_id\": $domain, \"mesh_rate_hz\": 60/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
  "$root/data/scenes/$scene_name.json" > "$tmp/scene.json"
# The recorder first, so that everything the server publishes can be compared with the file.
"$root/build/tools/viscera-record/viscera-record" --out "$tmp/session.mcap" --domain "$domain" --compression "${COMPRESSION:-zstd}" \
  > "$tmp/record.log" 2>&1 &
recorder=$!
sleep 1
"$root/build/server/runtime/viscera-server" --scene "$tmp/scene.json" > "$tmp/server.log" 2>&1 &
server=$!
for _ in $(seq 600); do grep -q "Hz physics" "$tmp/server.log" && break; sleep 0.1; done  # large meshes load for seconds
echo "record.sh: $seconds s of a 1 kHz press on $scene_name with 60 Hz frames, recorded ..."
start=$(date +%s.%N)
"$root/build/tools/haptic-client/haptic-client" --domain "$domain" --duration "$seconds" --depth 0.02 --quiet > "$tmp/client.log" 2>&1
sleep 1
# The recorder's CPU (user + system, clock ticks) and peak memory, just before it stops.
read -r utime stime < <(awk '{print $14, $15}' "/proc/$recorder/stat")
hwm_kb=$(awk '/VmHWM/ {print $2}' "/proc/$recorder/status")
wall=$(python3 -c "import time; print(time.time() - $start)")
kill -INT "$recorder"; wait "$recorder"
kill -INT "$server"; wait "$server" || true
[ -n "${KEEP:-}" ] && cp "$tmp/session.mcap" "$KEEP"
"$root/build/tools/viscera-record/viscera-record" info "$tmp/session.mcap" > "$tmp/info.txt"
python3 - "$tmp" "$seconds" "$scene_name" "$utime" "$stime" "$(getconf CLK_TCK)" "$hwm_kb" "$wall" "${COMPRESSION:-zstd}" \
  "$root/bench/results/record.json" <<'PY'
import json, os, platform, re, sys, time
tmp, seconds, scene, utime, stime, hz, hwm_kb, wall, compression, out = sys.argv[1:]
info = open(f"{tmp}/info.txt").read()
server = open(f"{tmp}/server.log").read()
rec_log = open(f"{tmp}/record.log").read()
per_topic = {}
for m in re.finditer(r"channel \d+: viscera_(\w+), source \S+, writer \S+, schema \d+: (\d+) messages", info):
    per_topic[m.group(1)] = per_topic.get(m.group(1), 0) + int(m.group(2))
span = float(re.search(r"messages over ([0-9.]+) s", info).group(1))
missing = int(re.search(r"drops: (\d+) missing", info).group(1))
end = re.search(r"stopped after (\d+) ticks.*?(\d+) forces sent.*?(\d+) mesh frames", server)
ticks, forces_sent, frames_sent = (int(x) for x in end.groups())
rates = [float(x) for x in re.findall(r"(\d+) Hz physics", server)]
payload_mb = float(re.search(r"([0-9.]+) MB of payloads", rec_log).group(1))
size = os.path.getsize(f"{tmp}/session.mcap")
cpu_s = (int(utime) + int(stime)) / int(hz)
cpu = open("/proc/cpuinfo").read()
model = re.search(r"model name\s*:\s*(.*)", cpu)
r = {
    "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    "machine": f"{model.group(1).strip() if model else platform.machine()}, {os.cpu_count()} CPUs",
    "scene": scene, "seconds": float(seconds), "compression": compression,
    "recording_span_s": span, "messages": per_topic, "file_mb": size / 1e6, "payload_mb": payload_mb,
    "mb_per_minute": size / 1e6 / (span / 60), "compression_ratio": payload_mb / (size / 1e6),
    "recorder_cpu_percent_of_one_core": 100 * cpu_s / float(wall), "recorder_peak_rss_mb": int(hwm_kb) / 1024,
    "missing_by_sequence": missing,
    "forces_published": forces_sent, "forces_recorded": per_topic.get("force_feedback", 0),
    "frames_published": frames_sent, "frames_recorded": per_topic.get("mesh_frame", 0),
    "physics_rate_hz_min": min(rates) if rates else 0, "physics_ticks": ticks,
}
json.dump(r, open(out, "w"), indent=1)
print(json.dumps(r, indent=1))
PY
