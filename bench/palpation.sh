#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The palpation exercise on the coarse and the fine nodule liver, side by side: for each seed (the
# nodule's place), viscera-trainer runs the exercise on a live server while the haptic client
# searches by touch (--script palpate --depth 0.006: it reads only the forces, docs/TRAINING.md) and
# marks the centre of the stiff area. Per run: passed or failed, the mark's distance from the
# nodule's surface, the peak force and the strain at the instrument, each against the exercise's
# limit, and the organ's largest edge strain (not scored: it grows as the mesh is refined). The scenes alternate per seed, so the machine's load falls on both alike. Prints a markdown
# table and writes bench/results/palpation.json.
# Usage: [SEEDS="1 2 3 4 5 6"] bench/palpation.sh
set -euo pipefail
if [ "${1:-}" = "--help" ] || [ "${1:-}" = "-h" ]; then sed -n '3,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0; fi
[ $# -eq 0 ] || { echo "palpation.sh: no arguments expected (SEEDS in the environment); see --help" >&2; exit 2; }
root="$(cd "$(dirname "$0")/.." && pwd)"
seeds="${SEEDS:-1 2 3 4 5 6}"
for s in $seeds; do [[ "$s" =~ ^[0-9]+$ ]] || { echo "palpation.sh: SEEDS: '$s' is not a whole number" >&2; exit 2; }; done
mkdir -p "$root/bench/results"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
b="$root/build"
tmp="$(mktemp -d)"; pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; [ -n "${KEEP:-}" ] && echo "kept $tmp" || rm -rf "$tmp"' EXIT
domain=$(( (RANDOM % 200) + 1 ))
mkdir -p "$tmp/scenes" "$tmp/exercises"
for scene in liver liver-nodule liver-nodule-12k; do
  sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
    "$root/data/scenes/$scene.json" > "$tmp/scenes/$scene.json"
done
cp "$root/data/exercises/palpation.json" "$root/data/exercises/palpation-12k.json" "$tmp/exercises/"
"$b/server/runtime/viscera-server" --scene "$tmp/scenes/liver.json" > "$tmp/server.log" 2>&1 & pids+=($!)
for _ in $(seq 100); do grep -q "Hz physics" "$tmp/server.log" && break; sleep 0.1; done
echo "| scene | seed | verdict | mark from the nodule [mm] (limit 10) | peak force [N] (limit 4) | strain at the instrument (limit 0.4) | largest edge strain | search [s] |"
echo "|---|---|---|---|---|---|---|---|"
: > "$tmp/runs.jsonl"
for seed in $seeds; do
  for exercise in palpation palpation-12k; do
    run="$tmp/$exercise-$seed"
    "$b/tools/viscera-trainer/viscera-trainer" run "$tmp/exercises/$exercise.json" --domain "$domain" --seed "$seed" --report-dir "$run" > "$run.live.log" 2>&1 & trainer=$!
    for _ in $(seq 600); do grep -q "trainer: exercise" "$run.live.log" && break; sleep 0.1; done
    start=$(date +%s.%N)
    "$b/tools/haptic-client/haptic-client" --domain "$domain" --client-id 21 --instrument 1 --script palpate --depth 0.006 --duration 110 \
      > "$run.client.log" 2>&1 || true
    wait $trainer || true
    python3 - "$run/$exercise.json" "$exercise" "$seed" "$(echo "$(date +%s.%N) - $start" | bc)" "$tmp/runs.jsonl" <<'PY'
import json, sys
path, exercise, seed, seconds, out = sys.argv[1:]
try:
    r = json.load(open(path))
except (OSError, ValueError) as e:
    print(f"| {exercise} | {seed} | no report ({e}) | | | | | |")
    sys.exit(0)
c = {x["name"]: x for x in r["criteria"]}
def v(name, scale=1.0, fmt="{:.2f}"):
    x = c.get(name)
    return "" if x is None else fmt.format(x["value"] * scale) + ("" if x["passed"] else " (over)")
scene = r.get("scene", exercise)
print(f"| {scene} | {seed} | {'passed' if r['passed'] else 'failed'} | {v('mark accuracy', 1e3, '{:.1f}')} | {v('peak force')} | "
      f"{v('strain at the instrument')} | {r['metrics']['max_edge_strain']:.2f} | {float(seconds):.0f} |")
with open(out, "a") as f:
    f.write(json.dumps({"exercise": exercise, "scene": scene, "seed": int(seed), "passed": r["passed"], "criteria": r["criteria"],
                        "wall_s": float(seconds)}) + "\n")
PY
  done
done
python3 - "$tmp/runs.jsonl" "$root/bench/results/palpation.json" "$(nproc)" "$(lscpu | sed -n 's/^Model name: *//p' | head -1)" <<'PY'
import json, sys, datetime
runs = [json.loads(l) for l in open(sys.argv[1])]
json.dump({"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="minutes"), "cpus": int(sys.argv[3]), "cpu": sys.argv[4],
           "runs": runs}, open(sys.argv[2], "w"), indent=1)
for ex in sorted({r["exercise"] for r in runs}):
    rs = [r for r in runs if r["exercise"] == ex]
    marked = [r for r in rs if any(c["name"] == "mark accuracy" and c["passed"] for c in r["criteria"])]
    print(f"{ex}: {sum(r['passed'] for r in rs)} of {len(rs)} passed, the nodule marked in {len(marked)} of {len(rs)}")
PY
echo "wrote bench/results/palpation.json"
