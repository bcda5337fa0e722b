#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A soak of viscera-server as a training session uses it: a probe client pressing the liver over
# and over, a grasper client grasping and pulling it, and an instructor's console making a request
# every 10 s (pause, resume, change the material, change the physics rate, annotate, show, load the
# scene again). The server's resident memory, threads and open file descriptors are sampled
# every SAMPLE_S seconds; at the end the growth per hour of each is fitted (least squares over the
# samples after the first WARMUP_S seconds), written to OUT/soak.json and plotted to OUT/soak.svg.
#
# Usage: bench/soak.sh [MINUTES]      (default 60)
#   SCENE=data/scenes/liver-12k.json  another scene
#   SAMPLE_S=60 WARMUP_S=300          sampling period and warm-up [s]
#   OUT=bench/results                 where soak.json and soak.svg go (the plot is also copied to docs/soak.svg
#                                     when OUT is the default)
#   BUILD=build                       the build to run
# Exit status: 0 when the server ran throughout and every client and request succeeded.
set -uo pipefail
if [ "${1:-}" = "--help" ] || [ "${1:-}" = "-h" ]; then sed -n '3,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
root="$(cd "$(dirname "$0")/.." && pwd)"
minutes="${1:-60}"
if ! [[ "$minutes" =~ ^[0-9]+([.][0-9]+)?$ ]] || [ "$(python3 -c "print(int($minutes > 0))")" != 1 ]; then
  echo "soak.sh: MINUTES must be a positive number, not '$minutes'" >&2; exit 2
fi
build="${BUILD:-$root/build}"
out="${OUT:-$root/bench/results}"
sample_s="${SAMPLE_S:-60}"
warmup_s="${WARMUP_S:-300}"
scene_src="${SCENE:-$root/data/scenes/liver.json}"
for b in server/runtime/viscera-server tools/haptic-client/haptic-client tools/viscera-control/viscera-control; do
  [ -x "$build/$b" ] || { echo "soak.sh: $build/$b is missing: build first (deploy/build.sh)" >&2; exit 2; }
done
mkdir -p "$out"
tmp="$(mktemp -d)"
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
domain=$(( (RANDOM % 200) + 1 ))
# The scene with absolute paths, on a domain of its own, in a scene folder the console can load from.
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
  "$scene_src" > "$tmp/soak.json"
end=$(( $(date +%s) + ${minutes%.*} * 60 + $(python3 -c "print(int(($minutes % 1) * 60))") ))
"$build/server/runtime/viscera-server" --scene "$tmp/soak.json" > "$tmp/server.log" 2>&1 &
server=$!
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; kill -INT "$server" 2>/dev/null || true; wait 2>/dev/null || true; rm -rf "$tmp"' EXIT
sleep 3
kill -0 "$server" 2>/dev/null || { echo "soak.sh: the server did not start:" >&2; cat "$tmp/server.log" >&2; exit 1; }
hc="$build/tools/haptic-client/haptic-client"
ctl="$build/tools/viscera-control/viscera-control"
# Each client a loop of runs, as trainees come and go; a failed run is counted.
( n=0; f=0; while [ "$(date +%s)" -lt "$end" ]; do
    "$hc" --domain "$domain" --client-id 1 --instrument 1 --script press --depth 0.02 --duration 12 --quiet > "$tmp/press.log" 2>&1 || f=$((f+1)); n=$((n+1))
    echo "$n $f" > "$tmp/press.count"; done ) &
pids+=($!)
( n=0; f=0; while [ "$(date +%s)" -lt "$end" ]; do
    "$hc" --domain "$domain" --client-id 2 --instrument 3 --script grasp --depth 0 --pull 0.015 --duration 8 --quiet > "$tmp/grasp.log" 2>&1 || f=$((f+1)); n=$((n+1))
    echo "$n $f" > "$tmp/grasp.count"; done ) &
pids+=($!)
( n=0; f=0; k=0
  while [ "$(date +%s)" -lt "$end" ]; do
    case $((k % 8)) in
      0) args=(pause) ;; 1) args=(resume) ;; 2) args=(material --youngs-modulus-pa 7000) ;; 3) args=(material --youngs-modulus-pa 5000) ;;
      4) args=(rate 500) ;; 5) args=(rate 1000) ;; 6) args=(annotate "soak request $k") ;; 7) args=(load soak) ;;
    esac
    "$ctl" "${args[@]}" --domain "$domain" --client-id 900 --timeout 30 >> "$tmp/console.log" 2>&1 || { f=$((f+1)); echo "FAILED: ${args[*]}" >> "$tmp/console.log"; }
    n=$((n+1)); k=$((k+1)); echo "$n $f" > "$tmp/console.count"
    sleep 10
  done ) &
pids+=($!)
# Sampling: seconds since start, resident memory [kB], threads, open file descriptors.
samples="$out/soak_samples.csv"
echo "t_s,rss_kb,threads,fds" > "$samples"
start=$(date +%s)
alive=1
while [ "$(date +%s)" -lt "$end" ]; do
  if ! kill -0 "$server" 2>/dev/null; then alive=0; break; fi
  t=$(( $(date +%s) - start ))
  rss=$(awk '/^VmRSS:/ {print $2}' "/proc/$server/status")
  threads=$(awk '/^Threads:/ {print $2}' "/proc/$server/status")
  fds=$(ls "/proc/$server/fd" | wc -l)
  echo "$t,$rss,$threads,$fds" >> "$samples"
  printf 'soak: t = %5d s  RSS %6d kB  threads %3d  fds %3d  runs: press %s, grasp %s, console %s (runs failed)\n' "$t" "$rss" "$threads" "$fds" \
    "$(cat "$tmp/press.count" 2>/dev/null || echo '0 0')" "$(cat "$tmp/grasp.count" 2>/dev/null || echo '0 0')" "$(cat "$tmp/console.count" 2>/dev/null || echo '0 0')"
  sleep "$sample_s"
done
wait "${pids[@]}" 2>/dev/null
pids=()
kill -INT "$server" 2>/dev/null; wait "$server"; rc_server=$?
tail -3 "$tmp/server.log"
grep FAILED "$tmp/console.log" | head -5
python3 "$root/bench/soak_report.py" "$samples" "$out" "$warmup_s" "$minutes" "$scene_src" "$alive" "$rc_server" \
  "$(cat "$tmp/press.count" 2>/dev/null)" "$(cat "$tmp/grasp.count" 2>/dev/null)" "$(cat "$tmp/console.count" 2>/dev/null)"
rc=$?
if [ "$out" = "$root/bench/results" ] && [ -f "$out/soak.svg" ]; then
  cp "$out/soak.svg" "$root/docs/soak.svg"
  python3 "$root/bench/performance_tables.py" "$root"
fi
exit $rc
