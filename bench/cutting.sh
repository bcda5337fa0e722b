#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Continuous cutting against pressing, side by side (docs/CUTTING.md, "Timing"): viscera-server on
# a bundled liver scene with a haptic client for SECONDS, once pressing with probe 1
# (--script press) and once cutting all the while with scalpel 4 (--script incise: the blade held
# in the tissue and drawn 6 cm along the top for the whole run, a sweep every tick), with the
# surface frames at 60 Hz watched by the client. Reports the server's missed slots and late ticks
# of each run, the difference in missed slots as a share of the slots, the surface's topology
# generation the client saw, the physics resets (an integration that failed), and the changes of
# the mesh with how often the organ's kinetic plus elastic energy rose at one (never, if the cut is
# right) and its largest change.
# REPEAT=N alternates the two N times. Usage: [SCENE=liver] [REPEAT=1] bench/cutting.sh [SECONDS]   (default 60)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ "${1:-}" = --help ] || [ "${1:-}" = -h ]; then sed -n '3,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0; fi
case "${1:-60}" in ''|*[!0-9]*|0) echo "$(basename "$0"): SECONDS: '${1:-}' is not a whole number of seconds above 0" >&2; exit 2;; esac
seconds="${1:-60}"
scene="${SCENE:-liver}"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
echo "| run | seconds | ticks | late ticks | missed slots | missed share | physics resets | surface generation seen | changes of the mesh | energy rose at | largest energy change |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for rep in $(seq "${REPEAT:-1}"); do
  for mode in press incise; do
    domain=$(( (RANDOM % 200) + 1 ))
    sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
      "$root/data/scenes/$scene.json" > "$tmp/scene.json"
    "$root/build/server/runtime/viscera-server" --scene "$tmp/scene.json" > "$tmp/server.log" 2>&1 &
    server=$!
    for _ in $(seq 100); do grep -q "DDS domain" "$tmp/server.log" && break; sleep 0.1; done
    if [ "$mode" = press ]; then
      args=(--instrument 1 --script press --depth 0.01)
    else
      args=(--instrument 4 --script incise --depth 0.015 --length 0.06)
    fi
    "$root/build/tools/haptic-client/haptic-client" --domain "$domain" --client-id 1 "${args[@]}" --duration "$seconds" --watch-mesh --quiet \
      > "$tmp/client.log" 2>&1 || true
    kill -INT "$server"; wait "$server" || true
    python3 - "$tmp/server.log" "$tmp/client.log" "$mode" "$seconds" <<'PY'
import re, sys
server, client, mode, seconds = open(sys.argv[1]).read(), open(sys.argv[2]).read(), sys.argv[3], sys.argv[4]
m = re.search(r"stopped after (\d+) ticks, (\d+) late, (\d+) missed slots, (\d+) physics resets", server)
g = re.search(r"surface generation (\d+), (\d+) vertices", client)
ticks, late, missed, resets = (int(x) for x in m.groups())
e = re.search(r"(\d+) changes of the mesh by cuts, kinetic plus elastic energy rose at (\d+) \(largest change (\S+) J\)", server)
changes, rises, largest = e.groups() if e else ("-", "-", "-")
print(f"| {mode} | {seconds} | {ticks} | {late} | {missed} | {100 * missed / (ticks + missed):.3f}% | {resets} | "
      f"{g.group(1) + ' (' + g.group(2) + ' vertices)' if g else '-'} | {changes} | {rises} | {largest + ' J' if e and changes != '0' else '-'} |")
PY
  done
done
