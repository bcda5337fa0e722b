#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What real-time scheduling and a pinned core change for the server (docs/DEPLOY.md, the systemd
# unit's CPUSchedulingPolicy=fifo): viscera-server on the liver with a haptic client pressing at
# 1 kHz, the machine loaded by LOAD busy processes (default: one per core), started plainly, with
# `chrt -f 50`, and with `chrt -f 50 taskset -c 1`; interleaved REPEAT times (the shared machine
# drifts). Prints each run's late ticks, missed slots and round trip. Needs root for chrt -f.
# Usage: [LOAD=N] [REPEAT=N] [SCENE=liver] bench/scheduling.sh [SECONDS]   (default 20 s)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-20}"; repeat="${REPEAT:-1}"; load="${LOAD:-$(nproc)}"; scene="${SCENE:-liver}"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; busy=()
trap 'kill "${busy[@]}" 2>/dev/null || true; rm -rf "$tmp"' EXIT
for _ in $(seq "$load"); do (while :; do :; done) & busy+=($!); done
echo "| start | late ticks | missed slots | ticks | round trip p50 / p99 / max [us] |"
echo "|---|---|---|---|---|"
run() {  # NAME PREFIX...
  local name="$1"; shift
  "$@" "$root/build/server/runtime/viscera-server" --scene "$root/data/scenes/$scene.json" --station sched --quiet > "$tmp/server.log" 2>&1 &
  local server=$!
  sleep 2
  "$root/build/tools/haptic-client/haptic-client" --station sched --duration "$seconds" --depth 0.02 --quiet --report "$tmp/hc.json" > "$tmp/hc.log" 2>&1 || true
  kill -INT "$server"; wait "$server" || true
  python3 - "$name" "$tmp/server.log" "$tmp/hc.json" <<'PY'
import json, re, sys
stop = re.search(r"stopped after (\d+) ticks, (\d+) late, (\d+) missed slots", open(sys.argv[2]).read())
rt = json.load(open(sys.argv[3]))["round_trip_us"]
print(f"| {sys.argv[1]} | {stop.group(2)} | {stop.group(3)} | {stop.group(1)} | {rt['p50']:.0f} / {rt['p99']:.0f} / {rt['max']:.0f} |")
PY
}
for _ in $(seq "$repeat"); do
  run "plain" env
  run "chrt -f 50" chrt -f 50
  run "chrt -f 50, taskset -c 1" chrt -f 50 taskset -c 1
done
echo "($load busy processes on $(nproc) cores, $scene, $seconds s each, $(date -u +%Y-%m-%dT%H:%MZ))"
