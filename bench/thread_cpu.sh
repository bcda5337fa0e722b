#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Where the two cores go while a haptic client presses the liver: CPU time of every thread of
# viscera-server and haptic-client over a window of the run (from /proc/PID/task/TID/stat, user +
# system), as a markdown table in % of one core, then the server's exit line.
# Usage: [DEPTH=0.02] [CLIENT_ARGS=...] bench/thread_cpu.sh [SCENE] [SECONDS]
#   SCENE: a scene of data/scenes (default liver-12k); SECONDS: the window (default 10), which
#   starts 6 s into the run (the organ built, the client connected).
set -euo pipefail
if [ "${1:-}" = "--help" ] || [ "${1:-}" = "-h" ]; then sed -n '3,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
root="$(cd "$(dirname "$0")/.." && pwd)"
scene="${1:-liver-12k}"; window="${2:-10}"
[ -f "$root/data/scenes/$scene.json" ] || { echo "thread_cpu.sh: no scene '$scene' in data/scenes" >&2; exit 2; }
[[ "$window" =~ ^[0-9]+$ ]] && [ "$window" -gt 0 ] || { echo "thread_cpu.sh: SECONDS: '$window' is not a positive whole number" >&2; exit 2; }
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; trap 'rm -rf "$tmp"' EXIT
domain=$(( (RANDOM % 200) + 1 ))
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
  "$root/data/scenes/$scene.json" > "$tmp/scene.json"
"$root/build/server/runtime/viscera-server" --scene "$tmp/scene.json" --quiet > "$tmp/server.log" 2>&1 &
server=$!
"$root/build/tools/haptic-client/haptic-client" --domain "$domain" --duration "$((window + 10))" --depth "${DEPTH:-0.02}" ${CLIENT_ARGS:-} \
  > /dev/null 2>&1 &
client=$!
sleep 6
snapshot() {  # process thread-id thread-name clock-ticks
  for p in "$server" "$client"; do
    for t in /proc/"$p"/task/*; do
      echo "$p $(basename "$t") $(tr ' ' _ < "$t/comm") $(awk '{print $14 + $15}' "$t/stat" 2>/dev/null || echo 0)"
    done
  done
}
snapshot > "$tmp/before"; sleep "$window"; snapshot > "$tmp/after"
wait "$client" || true
kill -INT "$server"; wait "$server" || true
python3 - "$tmp/before" "$tmp/after" "$server" "$window" "$(getconf CLK_TCK)" <<'PY'
import sys
before, after, server, window, hz = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), float(sys.argv[5])
start = {(p, t): int(j) for p, t, _, j in (l.split() for l in open(before))}
rows, total = [], {}
for p, t, name, j in (l.split() for l in open(after)):
    if (p, t) not in start: continue
    share = 100.0 * (int(j) - start[(p, t)]) / hz / window
    who = "viscera-server" if p == server else "haptic-client"
    total[who] = total.get(who, 0.0) + share
    if share > 0: rows.append((share, who, name))
print(f"| process | thread | CPU over {window:.0f} s [% of one core] |")
print("|---|---|---|")
for share, who, name in sorted(rows, reverse=True): print(f"| {who} | {name} | {share:.1f} |")
for who, share in total.items(): print(f"| {who} | all threads | {share:.1f} |")
PY
tail -1 "$tmp/server.log"
