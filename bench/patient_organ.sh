#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The patient's liver against the bundled one, side by side: viscera-mesh meshes the bundled CT
# label map to about 12,000 tetrahedra (docs/MESHING.md), then the server runs it and the bundled
# 12k liver in turn, RUNS times each, SECONDS a run, with one haptic client holding 1 N, as a station
# deploys them (FIFO priority 50 and 49; REALTIME=0 starts them plainly). Prints each run's missed
# slots (1 ms slots without a tick, over the slots of the run) and the explicit steps, the
# difference of the means in percentage points, and the two ticks' cost on one thread side by side
# (tick_bench, median of 5). Writes bench/results/patient_organ.json.
# Usage: [RUNS=3] [REALTIME=1] bench/patient_organ.sh [SECONDS]   (default 20 s)
set -euo pipefail
if [ "${1:-}" = "--help" ] || [ "${1:-}" = "-h" ]; then sed -n '3,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-20}"; runs="${RUNS:-3}"
[[ "$seconds" =~ ^[0-9]+$ ]] && [ "$seconds" -ge 5 ] || { echo "patient_organ.sh: SECONDS: '$seconds' is not a whole number of at least 5" >&2; exit 2; }
[[ "$runs" =~ ^[0-9]+$ ]] && [ "$runs" -ge 1 ] || { echo "patient_organ.sh: RUNS: '$runs' is not a positive whole number" >&2; exit 2; }
rt_server=(); rt_client=()
if [ "${REALTIME:-1}" != 0 ]; then
  chrt -f 50 true 2>/dev/null || { echo "patient_organ.sh: real-time priority is not allowed here (chrt -f 50 failed); REALTIME=0 runs without it" >&2; exit 2; }
  rt_server=(chrt -f 50); rt_client=(chrt -f 49)
fi
TARGETS="viscera-server haptic-client viscera-mesh tick_bench" "$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
b="$root/build"
tmp="$(mktemp -d)"; pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; rm -rf "$tmp"' EXIT
"$b/tools/viscera-mesh/viscera-mesh" "$root/data/label-maps/abdomen-totalsegmentator/example_seg.nii.gz" --organ 5 --organ-name liver \
  --region "4:gallbladder:$root/data/materials/gallbladder.json" --material "$root/data/materials/liver-viscoelastic.json" \
  --hold-touching 63 --hold-crop --tets 12000 --out "$tmp/patient" --name patient-liver --quiet
declare -A scene=([bundled]="$root/data/scenes/liver-12k.json" [patient]="$tmp/patient/patient-liver.json")
results="["
for run in $(seq "$runs"); do
  for which in bundled patient; do
    domain=$((120 + run))
    "${rt_server[@]}" "$b/server/runtime/viscera-server" --scene "${scene[$which]}" --domain "$domain" > "$tmp/server.log" 2>&1 &
    server=$!; pids=("$server")
    sleep 2
    "${rt_client[@]}" "$b/tools/haptic-client/haptic-client" --domain "$domain" --client-id 1 --instrument 2 --script hold --force 1 \
      --duration "$seconds" > "$tmp/client.log" 2>&1 || { echo "patient_organ.sh: the haptic client failed on $which:" >&2; tail -3 "$tmp/client.log" >&2; exit 1; }
    kill -INT "$server"; wait "$server" || true
    line="$(grep "stopped after" "$tmp/server.log")"
    ticks="$(sed -E 's/.*stopped after ([0-9]+) ticks.*/\1/' <<< "$line")"
    missed="$(sed -E 's/.* ([0-9]+) missed slots.*/\1/' <<< "$line")"
    step="$(grep -o "explicit step [0-9.e-]* s" "$tmp/server.log" | head -1 | awk '{print $3}')"
    rate="$(python3 -c "print(f'{100 * $missed / ($ticks + $missed):.2f}')")"
    echo "run $run  $which  ticks $ticks  missed slots $missed ($rate%)  explicit step $step s"
    results+="{\"run\": $run, \"scene\": \"$which\", \"ticks\": $ticks, \"missed\": $missed, \"missed_percent\": $rate, \"explicit_step_s\": $step},"
  done
done
mkdir -p "$root/bench/results"
echo "${results%,}]" > "$root/bench/results/patient_organ.json"
# The missed slots of a loaded shared machine vary far more between runs than between the scenes:
# the tick's cost on one thread, the two scenes in one run, is what decides them on a quiet one.
VISCERA_TICK_SCENE="$tmp/patient/patient-liver.json" "$b/bench/tick_bench" --benchmark_filter='Tick/(liver-12k|patient-liver)/threads:1/' \
  --benchmark_repetitions=5 --benchmark_report_aggregates_only=true --benchmark_format=json > "$tmp/tick.json" 2>/dev/null
python3 - "$root/bench/results/patient_organ.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
mean = {s: sum(x["missed_percent"] for x in r if x["scene"] == s) / max(1, sum(1 for x in r if x["scene"] == s)) for s in ("bundled", "patient")}
step = {s: next(x["explicit_step_s"] for x in r if x["scene"] == s) for s in ("bundled", "patient")}
print(f"| scene | missed slots (mean of runs) | explicit step |\n|---|---|---|")
for s in ("bundled", "patient"):
    print(f"| {s} 12k liver | {mean[s]:.2f}% | {step[s] * 1e3:.3f} ms |")
print(f"patient - bundled: {mean['patient'] - mean['bundled']:+.2f} percentage points; step ratio patient/bundled {step['patient'] / step['bundled']:.2f}")
PY
python3 - "$tmp/tick.json" <<'PY'
import json, sys
median = {b["run_name"].split("/")[1]: b["real_time"] for b in json.load(open(sys.argv[1]))["benchmarks"] if b.get("aggregate_name") == "median"}
print(f"tick on one thread (median of 5): bundled {median['liver-12k']:.0f} us, patient {median['patient-liver']:.0f} us, ratio {median['patient-liver'] / median['liver-12k']:.3f}")
PY
