#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain: each exercise (docs/TRAINING.md) run by
# viscera-trainer on a live server, performed by a scripted haptic client once well and once
# badly, and recorded by viscera-record. The good performance passes, the bad one fails for the
# right named reason (too much force, the lobe dropped, off the incision's line, the wrong place marked), and the score
# computed afterwards from the recording equals the live one in every number. The good palpation
# is performed by a client that searches by touch (the forces it feels), never by reading the
# scene, and must mark the nodule.
# Usage: training_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; [ -n "${KEEP:-}" ] && cp -r "$tmp" /tmp/training-test/; show_output; rm -rf "$tmp"' EXIT
rec="$build/tools/viscera-record/viscera-record"
trainer="$build/tools/viscera-trainer/viscera-trainer"
hc="$build/tools/haptic-client/haptic-client"
ctl="$build/tools/viscera-control/viscera-control"

# The scene folder: the liver and the liver with a hidden nodule, on this test's domain.
scenes="$tmp/scenes"; mkdir -p "$scenes"
cp "$scene" "$scenes/liver.json"
for scene_name in liver-nodule liver-titin; do
  sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$src/data/meshes/#; s#\"../materials/#\"$src/data/materials/#" \
    "$src/data/scenes/$scene_name.json" > "$scenes/$scene_name.json"
done
# The shipped exercises with shorter time limits, so that a bad performance ends soon.
ex="$tmp/exercises"; mkdir -p "$ex"
python3 - "$src/data/exercises" "$ex" <<'PY'
import json, sys
for name, limit in (("force-drill", 20), ("force-drill-titin", 20), ("retraction", 15), ("palpation", 90), ("incision", 20)):
    e = json.load(open(f"{sys.argv[1]}/{name}.json"))
    e["time_limit_s"] = limit
    # The titin-fitted organ runs at a third of real time or less under a press (its stiffening
    # takes 8 sub-steps of 0.4 ms on this machine: 270-290 ticks/s, the old build and the new alike,
    # 2026-12-07): the client's 18 s give it 5-7 s of simulated time, so the hold it must show is 4 s.
    if name == "force-drill-titin":
        e["force_drill"]["hold_s"] = 4
    json.dump(e, open(f"{sys.argv[2]}/{name}.json", "w"), indent=1)
PY
"$build/server/runtime/viscera-server" --scene "$scenes/liver.json" > "$tmp/server.log" 2>&1 & server=$!; pids+=($server)
sleep 1.5

# perform NAME EXERCISE SEED CLIENT-ARGS...: the trainer live, a recorder beside it, the client;
# then the score of the recording. Sets rc_live_NAME, rc_score_NAME.
perform() {
  local name="$1" exercise="$2" seed="$3"; shift 3
  "$rec" --out "$tmp/$name.mcap" --domain "$domain" --quiet > "$tmp/$name.rec.log" 2>&1 & local recorder=$!
  wait_for "recording DDS domain" "$tmp/$name.rec.log" || true
  local seed_arg=(); [ "$seed" != "-" ] && seed_arg=(--seed "$seed")
  "$trainer" run "$ex/$exercise.json" --domain "$domain" "${seed_arg[@]}" --report-dir "$tmp/live-$name" > "$tmp/$name.live.log" 2>&1 & local tr=$!
  wait_for "trainer: exercise" "$tmp/$name.live.log" 300 || true
  "$hc" --domain "$domain" --client-id 21 "$@" > "$tmp/$name.client.log" 2>&1
  wait $tr; eval "rc_live_$name=$?"
  kill -INT $recorder; wait $recorder
  "$trainer" score "$ex/$exercise.json" "$tmp/$name.mcap" --report-dir "$tmp/score-$name" > "$tmp/$name.score.log" 2>&1
  eval "rc_score_$name=$?"
  echo "--- $name (live, then from the recording):"; cat "$tmp/$name.live.log"; grep -v "^trainer:" "$tmp/$name.score.log" | head -3
  grep -E "^palpate: [0-9]+ points|stiffest of" "$tmp/$name.client.log"
}

perform drill_good force-drill - --instrument 1 --script hold --force 1.0 --duration 15 --quiet
perform drill_bad force-drill - --instrument 1 --script hold --force 2.4 --duration 8 --quiet
# The drill on the tissue viscera-lab fitted to the titin data (its material file, by a scene).
perform drill_titin force-drill-titin - --instrument 1 --script hold --force 1.0 --duration 18 --quiet
perform retraction_good retraction - --instrument 3 --script grasp --depth 0.005 --pull 0.02 --hold 7 --duration 12 --quiet
perform retraction_bad retraction - --instrument 3 --script grasp --depth 0.005 --pull 0.02 --hold 1 --duration 6 --quiet
# The incision: a 5 cm cut 1 cm deep (the script sinks 11 mm below the tip's height at contact, its
# 1 mm tip's lowest point 10 mm below where it touched); then one 8 mm beside the line.
perform incision_good incision - --instrument 4 --script incise --depth 0.011 --length 0.05 --duration 4 --quiet
perform incision_bad incision - --instrument 4 --script incise --depth 0.011 --length 0.05 --offset-y 0.008 --duration 4 --quiet
perform palpation_good palpation 3 --instrument 1 --script palpate --depth 0.006 --duration 80
"$ctl" show --domain "$domain" > "$tmp/nodule.log" 2>&1
# The bad palpation marks, pressing gently, the place the good one touched that lies farthest
# from the nodule (the test reads the truth; the palpating client never did).
python3 - "$tmp/nodule.log" "$tmp/palpation_good.client.log" "$tmp/wrong-place.csv" <<'PY'
import re, sys
c = re.search(r"region nodule: sphere of radius ([0-9.e-]+) m at \(([-0-9.e]+), ([-0-9.e]+), ([-0-9.e]+)\)", open(sys.argv[1]).read())
cx, cy = float(c.group(2)), float(c.group(3))
points = [tuple(map(float, m.groups())) for m in re.finditer(r"palpate: \(([-0-9.]+), ([-0-9.]+)\) m, contact at z ([-0-9.]+) m: .* at \d+ mm$",
                                                             open(sys.argv[2]).read(), re.M)]
x, y, z = max(points, key=lambda p: (p[0] - cx) ** 2 + (p[1] - cy) ** 2)
rows = [(0.0, z + 0.01, 0), (1.0, z - 0.003, 0), (1.4, z - 0.003, 0), (1.45, z - 0.003, 1), (1.6, z - 0.003, 0), (2.5, z + 0.01, 0)]
with open(sys.argv[3], "w") as f:
    f.write("time_s,x_m,y_m,z_m,jaw_rad,buttons\n")
    for t, zz, b in rows:
        f.write(f"{t},{x},{y},{zz},0.5,{b}\n")
print(f"wrong place: ({x:.3f}, {y:.3f}) m, {((x - cx) ** 2 + (y - cy) ** 2) ** 0.5 * 1000:.0f} mm from the nodule's centre across")
PY
perform palpation_bad palpation 3 --instrument 1 --trajectory "$tmp/wrong-place.csv" --frame scene --quiet
# A trainer stopped by a signal mid-exercise says so (it used to blame the instrument).
"$trainer" run "$ex/force-drill.json" --domain "$domain" > "$tmp/stopped.log" 2>&1 & tr=$!
wait_for "trainer: exercise" "$tmp/stopped.log" 300 || true
"$hc" --domain "$domain" --client-id 21 --instrument 1 --script hold --force 1.0 --duration 2 --quiet > /dev/null 2>&1
kill -TERM $tr; wait $tr; rc_stopped=$?
grep -iE "stopped" "$tmp/stopped.log"
check "a trainer stopped by SIGTERM says it was stopped (rc $rc_stopped)" \
  "grep -q 'the trainer was stopped (SIGINT or SIGTERM)' '$tmp/stopped.log' && ! grep -q 'the instrument stopped' '$tmp/stopped.log'"
kill -INT $server; wait $server; rc_server=$?
grep region "$tmp/nodule.log"

check "force drill, held at 1.0 N: passed (rc $rc_live_drill_good)" "[ $rc_live_drill_good -eq 0 ] && grep -q 'PASSED' '$tmp/drill_good.live.log'"
check "force drill, pressed at 2.4 N: failed for too much force (rc $rc_live_drill_bad)" \
  "[ $rc_live_drill_bad -eq 1 ] && grep -q 'too much force' '$tmp/drill_bad.live.log'"
check "force drill on the lab-fitted titin tissue, held at 1.0 N: passed (rc $rc_live_drill_titin)" \
  "[ $rc_live_drill_titin -eq 0 ] && grep -q 'PASSED' '$tmp/drill_titin.live.log' && grep -q 'liver-titin' '$tmp/drill_titin.live.log'"
check "retraction, lifted and held: passed (rc $rc_live_retraction_good)" "[ $rc_live_retraction_good -eq 0 ]"
check "retraction, let go after 1 s: failed, the lobe dropped (rc $rc_live_retraction_bad)" \
  "[ $rc_live_retraction_bad -eq 1 ] && grep -q 'the lobe was dropped' '$tmp/retraction_bad.live.log'"
# The palpation by touch: it searched, found the nodule by the forces alone and marked it.
check "palpation by touch: the nodule found and marked, passed (rc $rc_live_palpation_good)" \
  "[ $rc_live_palpation_good -eq 0 ] && grep -q 'stiffest of' '$tmp/palpation_good.client.log' && grep -q 'trainer: marked at' '$tmp/palpation_good.live.log'"
grep -E "PASSED|FAILED|wrong place|mark accuracy" "$tmp/palpation_good.live.log" | sed 's/^/palpation by touch: /'
python3 - "$tmp/palpation_good.client.log" <<'PY'
import re, sys
rows = re.findall(r"palpate: .*: ([0-9.]+) N at 3 mm, ([0-9.]+) N at 6 mm$", open(sys.argv[1]).read(), re.M)
drops = sum(1 for a, b in rows if float(b) < float(a))
print(f"palpation by touch: {len(rows)} presses, the force at 6 mm below the force at 3 mm in {drops} (contact lost as the tip goes deeper)")
PY
check "palpation marked elsewhere: failed, the wrong place marked (rc $rc_live_palpation_bad)" \
  "[ $rc_live_palpation_bad -eq 1 ] && grep -q 'the wrong place was marked' '$tmp/palpation_bad.live.log'"
check "incision along the line, 1 cm deep: passed (rc $rc_live_incision_good)" "[ $rc_live_incision_good -eq 0 ] && grep -q 'PASSED' '$tmp/incision_good.live.log'"
check "incision 8 mm beside the line: failed, off the line (rc $rc_live_incision_bad)" \
  "[ $rc_live_incision_bad -eq 1 ] && grep -q 'off the line' '$tmp/incision_bad.live.log'"
for n in drill_good drill_bad drill_titin retraction_good retraction_bad incision_good incision_bad palpation_good palpation_bad; do
  live_rc="rc_live_$n"; score_rc="rc_score_$n"
  check "$n: the score from the recording gives the same verdict (rc ${!live_rc} ${!score_rc})" "[ ${!live_rc} -eq ${!score_rc} ]"
done
pycheck "$tmp" <<'PY'
import glob, json, os, sys
tmp = sys.argv[1]
ok = True
for live in sorted(glob.glob(f"{tmp}/live-*/*.json")):
    name = live.split("/live-")[1].split("/")[0]
    later = live.replace("/live-", "/score-")
    a, b = json.load(open(live)), json.load(open(later))
    if a != b:
        ok = False
        for k in sorted(set(a) | set(b)):
            if a.get(k) != b.get(k):
                print(f"FAIL {name}: live {k} = {a.get(k)} but from the recording {b.get(k)}")
    else:
        m = a["metrics"]
        print(f"{name}: live and recorded agree: {m['force_samples']} forces, peak {m['peak_force_n']:.3f} N, "
              f"path {m['path_length_m']:.4f} m, hold {m['longest_hold_s']:.3f} s, time {m['time_s']:.3f} s, passed {a['passed']}")
    if a["metrics"]["force_samples_without_command"] > 0.01 * max(1, a["metrics"]["force_samples"]):
        ok = False
        print(f"FAIL {name}: {a['metrics']['force_samples_without_command']} forces without their command")
sys.exit(0 if ok else 1)
PY
# The server's status line carries the largest tissue strain at an instrument: 0 before any client
# came, positive while one held the tissue, and never above what the trainers received, tick by
# tick, in their forces (10% and a thousandth of slack: the lines sample the same measure; one
# 2 s hold below has no report, at the drill's own force).
pycheck "$tmp" <<'PY'
import glob, json, re, sys
tmp = sys.argv[1]
lines = [float(m) for m in re.findall(r"Hz physics.*, tip strain ([0-9.]+), rejected", open(f"{tmp}/server.log").read())]
received = max(json.load(open(f))["metrics"]["max_tip_strain"] for f in glob.glob(f"{tmp}/live-*/*.json"))
assert len(lines) > 30, f"{len(lines)} status lines with a tip strain"
assert lines[0] == 0.0, f"the first status line, before any client, gives tip strain {lines[0]}"
assert max(lines) > 0.01, f"no status line shows the tissue strained (largest {max(lines)})"
assert max(lines) <= 1.1 * received + 1e-3, f"a status line gives tip strain {max(lines)}, the trainers received at most {received}"
print(f"[ figure ] status lines: tip strain up to {max(lines):.3f}, {sum(1 for x in lines if x > 0)} of {len(lines)} lines positive; trainers received up to {received:.3f}")
PY
check "server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"

# Bad exercise files: one line naming the file and the field, exit 2.
printf '{"name": "x", "kind": "force_drill", "scene": "liver", "colour": 1}' > "$tmp/unknown.json"
printf '{"name": "x", "kind": "force_drill", "scene": "liver", "time_limit_s": -5}' > "$tmp/range.json"
"$trainer" score "$tmp/unknown.json" "$tmp/drill_good.mcap" > /dev/null 2> "$tmp/bad1.err"; rc1=$?
"$trainer" score "$tmp/range.json" "$tmp/drill_good.mcap" > /dev/null 2> "$tmp/bad2.err"; rc2=$?
"$trainer" run "$ex/force-drill.json" --domain "$domain" --seed -1 > /dev/null 2> "$tmp/bad3.err"; rc3=$?
cat "$tmp/bad1.err" "$tmp/bad2.err" "$tmp/bad3.err"
check "unknown field: exit 2 naming file and field" "[ $rc1 -eq 2 ] && grep -q 'unknown.json: colour: unknown field' '$tmp/bad1.err' && [ \$(wc -l < '$tmp/bad1.err') -eq 1 ]"
check "value out of range: exit 2 naming file and field" "[ $rc2 -eq 2 ] && grep -q 'range.json: time_limit_s' '$tmp/bad2.err'"
check "bad command line: exit 2" "[ $rc3 -eq 2 ]"
finish
