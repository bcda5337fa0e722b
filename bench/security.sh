#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# What DDS Security costs a station (docs/DEPLOY.md): viscera-server on the liver with a haptic
# client pressing at 1 kHz, once with loopback.xml and once with secure.xml added (authentication,
# access control, every stream encrypted; the test PKI of deploy/dds/make-test-pki.sh),
# interleaved REPEAT times (the shared machine drifts). Prints each run's late ticks, missed
# slots, the client's round trip, and the server's CPU time per second of run.
# Usage: [REPEAT=N] [SCENE=liver] bench/security.sh [SECONDS]   (default 20 s)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-20}"; repeat="${REPEAT:-2}"; scene="${SCENE:-liver}"
"$root/deploy/build.sh" "$root/build" >/dev/null
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
plugins=$(dirname "$(dpkg -L libddsc0debian | grep 'libdds_security_auth.so$' | head -1)")
export VISCERA_DDS_PLUGINS="$plugins" VISCERA_PKI="$tmp/pki"
"$root/deploy/dds/make-test-pki.sh" "$tmp/pki" sec > /dev/null
plain="file://$root/deploy/dds/loopback.xml"
secure="$plain,file://$root/deploy/dds/secure.xml"
echo "| DDS | late ticks | missed slots | ticks | server CPU [s/s] | round trip p50 / p99 / max [us] |"
echo "|---|---|---|---|---|---|"
run() {  # NAME URI
  env CYCLONEDDS_URI="$2" VISCERA_IDENTITY=server-sec "$root/build/server/runtime/viscera-server" --scene "$root/data/scenes/$scene.json" \
    --station sec --quiet > "$tmp/server.log" 2>&1 &
  local server=$!
  sleep 3
  local before; before=$(awk '{print $14 + $15}' "/proc/$server/stat")
  env CYCLONEDDS_URI="$2" VISCERA_IDENTITY=haptic-sec "$root/build/tools/haptic-client/haptic-client" --station sec --duration "$seconds" \
    --depth 0.02 --quiet --report "$tmp/hc.json" > "$tmp/hc.log" 2>&1 || true
  local after; after=$(awk '{print $14 + $15}' "/proc/$server/stat")
  kill -INT "$server"; wait "$server" || true
  python3 - "$1" "$tmp/server.log" "$tmp/hc.json" "$before" "$after" "$(getconf CLK_TCK)" "$seconds" <<'PY'
import json, re, sys
stop = re.search(r"stopped after (\d+) ticks, (\d+) late, (\d+) missed slots", open(sys.argv[2]).read())
rt = json.load(open(sys.argv[3]))["round_trip_us"]
cpu = (int(sys.argv[5]) - int(sys.argv[4])) / int(sys.argv[6]) / float(sys.argv[7])
print(f"| {sys.argv[1]} | {stop.group(2)} | {stop.group(3)} | {stop.group(1)} | {cpu:.2f} | {rt['p50']:.0f} / {rt['p99']:.0f} / {rt['max']:.0f} |")
PY
}
for _ in $(seq "$repeat"); do
  run "plain" "$plain"
  run "secure" "$secure"
done
echo "($scene, one client pressing, $seconds s each, $(nproc) cores, $(date -u +%Y-%m-%dT%H:%MZ))"
