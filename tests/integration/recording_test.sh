#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain: a scripted session (a press, a material
# change, a material file refused and one taken whole, a grasp and lift, an annotation, the first client pressing again under the same id)
# recorded by viscera-record; the file judged by the
# official MCAP reader (@mcap/core under Node: channels, schemas, counts against the writers'
# sequence numbers, no gaps, monotonic log times, attachments) and every payload by viscera's own
# decoders; a second recorder (lz4) killed with SIGKILL mid-session, recovered, and the recovered
# file checked against what the official reader gets from the cut file; the session replayed at 2x
# onto a partition of its own and recorded there by a third recorder (the forces and frames
# arrive in the original order at twice the pace); re-simulated in lockstep bit for bit, and with
# another material named at its first divergence; and bad recordings refused with one line each.
# Usage: recording_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; [ -n "${KEEP:-}" ] && cp -r "$tmp" /tmp/rt2/; show_output; rm -rf "$tmp"' EXIT
rec="$build/tools/viscera-record/viscera-record"
replay="$build/tools/viscera-replay/viscera-replay"
hc="$build/tools/haptic-client/haptic-client"
ctl="$build/tools/viscera-control/viscera-control"
node_dir="$src/tests/node"
[ -d "$node_dir/node_modules/@mcap/core" ] || { echo "FAIL @mcap/core is not installed (deploy/install-deps.sh runs npm ci in tests/node)"; exit 1; }

# --- The live session, recorded twice --------------------------------------------------------
"$build/server/runtime/viscera-server" --scene "$scene" > "$tmp/server.log" 2>&1 & server=$!; pids+=($server)
"$rec" --out "$tmp/session.mcap" --domain "$domain" > "$tmp/rec.log" 2>&1 & recorder=$!; pids+=($recorder)
"$rec" --out "$tmp/killed.mcap" --domain "$domain" --compression lz4 --chunk-s 0.5 --quiet > "$tmp/killed.log" 2>&1 & victim=$!; pids+=($victim)
wait_for "recording DDS domain" "$tmp/rec.log"; wait_for "recording DDS domain" "$tmp/killed.log"
sleep 1  # discovery: the recorders' readers matched before the first command
"$hc" --domain "$domain" --client-id 11 --instrument 1 --duration 3 --depth 0.01 --quiet > "$tmp/press.log" 2>&1 & press=$!
sleep 1.5
"$ctl" annotate "bookmark: first press" --domain "$domain" --client-id 901 > "$tmp/control.log" 2>&1; rc_note=$?
wait $press; rc_press=$?
"$ctl" material --youngs-modulus-pa 6500 --domain "$domain" >> "$tmp/control.log" 2>&1; rc_material=$?
# A material file that does not read (a shape of the energy form without the energy form), refused
# naming its field; then the lab's fitted titin material, sent whole (schema 14), for the rest.
printf '{"name": "bad", "density_kg_m3": 1000, "elasticity": {"type": "isotropic", "youngs_modulus_pa": 5000, "poisson_ratio": 0.4},
 "viscoelasticity": {"model": "relaxation_spectrum", "qlv_stiffening": 2, "qlv_shape": "odd_polynomial"}}' > "$tmp/bad shape.json"
"$ctl" material --file "$tmp/bad shape.json" --domain "$domain" > "$tmp/bad-material.log" 2>&1; rc_bad_material=$?
"$ctl" material --file "$src/docs/lab/titin/material.json" --domain "$domain" >> "$tmp/control.log" 2>&1; rc_file=$?
"$hc" --domain "$domain" --client-id 12 --instrument 3 --script grasp --duration 3 --depth 0.004 --pull 0.01 --quiet > "$tmp/grasp.log" 2>&1 & grasp=$!
sleep 1.5
kill -KILL "$victim"
wait $grasp; rc_grasp=$?
# The first client again, with the same id: its commands are numbered from 1 again.
"$hc" --domain "$domain" --client-id 11 --instrument 1 --duration 1.5 --depth 0.01 --quiet > "$tmp/press2.log" 2>&1; rc_press2=$?
sleep 0.3
kill -INT "$recorder"; wait "$recorder"; rc_rec=$?
kill -INT "$server"; wait "$server"; rc_server=$?
cat "$tmp/control.log" "$tmp/press.log" "$tmp/grasp.log"; tail -3 "$tmp/rec.log"; [ $rc_server -eq 0 ] || cat "$tmp/server.log"
check "the session ran (press $rc_press, annotation $rc_note, material $rc_material, grasp $rc_grasp, press again $rc_press2, server $rc_server)" \
  "[ $rc_press -eq 0 ] && [ $rc_note -eq 0 ] && [ $rc_material -eq 0 ] && [ $rc_grasp -eq 0 ] && [ $rc_press2 -eq 0 ] && [ $rc_server -eq 0 ]"
check "the recorder closed its file (rc $rc_rec)" "[ $rc_rec -eq 0 ]"
cat "$tmp/bad-material.log"
check "a material file that does not read is refused naming its field (rc $rc_bad_material)" \
  "[ $rc_bad_material -eq 1 ] && grep -q 'refused: material file bad_shape.json: set_material: viscoelasticity.qlv_shape' '$tmp/bad-material.log'"
check "the lab's titin material file is taken whole (rc $rc_file)" \
  "[ $rc_file -eq 0 ] && grep -q 'changed to material file material.json' '$tmp/control.log' && grep -q 'material titin-passive-muscle' '$tmp/control.log'"

# --- The official reader's verdict -----------------------------------------------------------
node "$node_dir/check_mcap.mjs" "$tmp/session.mcap" > "$tmp/official.json"; rc_official=$?
check "@mcap/core reads the recording, streamed and indexed (rc $rc_official)" "[ $rc_official -eq 0 ]"
pycheck "$tmp/official.json" <<'PY'
import json, sys
o = json.load(open(sys.argv[1]))
topics = {}
for c in o["channels"]:
    topics.setdefault(c["topic"], []).append(c)
want = ["viscera_instrument_command", "viscera_force_feedback", "viscera_session_request", "viscera_scene_state",
        "viscera_telemetry", "viscera_surface_topology", "viscera_mesh_frame", "viscera_event"]
problems = [f"no channel {t}" for t in want if t not in topics]
for c in o["channels"]:
    name = f'{c["topic"]} (writer {c["metadata"].get("writer")})'
    if c["messageEncoding"] != "flatbuffer" or c["schemaEncoding"] != "flatbuffer" or not (c["schemaName"] or "").startswith("viscera.wire."):
        problems.append(f"{name}: encodings {c['messageEncoding']}/{c['schemaEncoding']}, schema {c['schemaName']}")
    if c["streamCount"] != c["indexCount"] or c["streamCount"] != o["statistics"]["channelMessageCounts"][str(c["id"])]:
        problems.append(f"{name}: {c['streamCount']} streamed, {c['indexCount']} indexed, statistics {o['statistics']['channelMessageCounts'][str(c['id'])]}")
# The writers of commands and forces began after the recorder joined: every sample they published is here.
for c in o["channels"]:
    if c["topic"] in ("viscera_force_feedback", "viscera_instrument_command") and o["writers"][f'writer {c["metadata"]["writer"]}']["first"] != 1:
        problems.append(f'{c["topic"]}: its writer\'s first sample in the file is not its first published')
for w, s in o["writers"].items():
    if s["missing"]:
        problems.append(f"{w}: {s['missing']} sequence numbers missing between {s['first']} and {s['last']}")
if not o["stream"]["monotonicLogTimes"]:
    problems.append("log times decrease somewhere in file order")
if o["indexedMessages"] != o["statistics"]["messageCount"]:
    problems.append(f'{o["indexedMessages"]} messages through the index, statistics say {o["statistics"]["messageCount"]}')
counts = {t: sum(c["streamCount"] for c in cs) for t, cs in topics.items()}
# 1 kHz for about 6 s of instruments, 60 Hz frames, telemetry: the counts must be of that order.
if counts.get("viscera_force_feedback", 0) < 4000 or counts.get("viscera_instrument_command", 0) < 4000:
    problems.append(f"too few forces or commands: {counts}")
if counts.get("viscera_mesh_frame", 0) < 150:
    problems.append(f"too few mesh frames: {counts}")
roles = sorted(a["name"].split("/")[0] for a in o["attachments"])
if roles != ["material", "mesh", "scene"]:
    problems.append(f"attachments {[a['name'] for a in o['attachments']]}: want the scene, its mesh and its material once each")
meta = {m["name"]: m["metadata"] for m in o["metadata"]}
if meta.get("viscera.drops", {}).get("missing") != "0":
    problems.append(f'drops: {meta.get("viscera.drops")}')
if "viscera.scene" not in meta or "viscera.recording" not in meta:
    problems.append(f"metadata: {list(meta)}")
print("official reader:", {k.replace("viscera_", ""): v for k, v in sorted(counts.items())}, f'{o["statistics"]["chunkCount"]} chunks')
for p in problems:
    print("  ", p)
sys.exit(1 if problems else 0)
PY
"$rec" info "$tmp/session.mcap" --verify > "$tmp/info.txt"; rc_info=$?
cat "$tmp/info.txt" | grep -E "messages over|payloads|drops:"
check "every payload decodes with viscera's decoders (info --verify rc $rc_info)" "[ $rc_info -eq 0 ] && grep -q ', 0 do not' '$tmp/info.txt'"
# The events: the annotation, the claims, the material change and the grasp are there.
pycheck "$tmp/official.json" "$tmp/info.txt" <<'PY'
import sys
info = open(sys.argv[2]).read()
ok = "scene (generation" in info and "material: " in info and "mesh: " in info
print("scene files in the recording:", ok)
sys.exit(0 if ok else 1)
PY

# --- A recorder killed mid-session -----------------------------------------------------------
node "$node_dir/check_mcap.mjs" --cut "$tmp/killed.mcap" > "$tmp/cut.json"; cat "$tmp/cut.json"
"$rec" recover "$tmp/killed.mcap" "$tmp/recovered.mcap" > "$tmp/recover.log" 2>&1; rc_recover=$?; cat "$tmp/recover.log"
node "$node_dir/check_mcap.mjs" "$tmp/recovered.mcap" > "$tmp/recovered.json"; rc_rofficial=$?
# Exit 0: the kill fell between two records, nothing in the file was lost; exit 1: it fell inside a
# chunk being written, whose bytes are lost (said, with where).
killed_size=$(stat -c %s "$tmp/killed.mcap")
check "recover wrote a file (rc $rc_recover) the official reader accepts (rc $rc_rofficial)" \
  "[ $rc_rofficial -eq 0 ] && { [ $rc_recover -eq 0 ] || { [ $rc_recover -eq 1 ] && grep -q 'lost bytes [0-9]* to $killed_size ' '$tmp/recover.log'; }; }"
pycheck "$tmp/cut.json" "$tmp/recovered.json" "$tmp/recover.log" <<'PY'
import json, re, sys
cut, rec, log = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), open(sys.argv[3]).read()
saved = int(re.search(r"saved (\d+) messages", log).group(1))
n = rec["statistics"]["messageCount"]
print(f"killed recorder: the official reader streams {cut['messages']} messages from the cut file; recover saved {saved}; the recovered file holds {n}")
sys.exit(0 if cut["messages"] > 1000 and n == cut["messages"] == saved and not cut["complete"] else 1)
PY

# --- Replay at 2x onto a partition of its own, recorded there -------------------------------
"$rec" --out "$tmp/replayed.mcap" --domain "$domain" --station replay-test --quiet > "$tmp/rec2.log" 2>&1 & recorder2=$!; pids+=($recorder2)
wait_for "recording DDS domain" "$tmp/rec2.log"
"$replay" play "$tmp/session.mcap" --rate 2 --station replay-test --domain "$domain" --no-keys --quiet > "$tmp/play.log" 2>&1; rc_play=$?
sleep 0.3
kill -INT "$recorder2"; wait "$recorder2"; rc_rec2=$?
cat "$tmp/play.log"
check "the replay ran (rc $rc_play) and was recorded (rc $rc_rec2)" "[ $rc_play -eq 0 ] && [ $rc_rec2 -eq 0 ]"
node "$node_dir/compare_replay.mjs" "$tmp/session.mcap" "$tmp/replayed.mcap" viscera_force_feedback viscera_mesh_frame > "$tmp/compare.json"; rc_compare=$?
check "compare_replay read both (rc $rc_compare)" "[ $rc_compare -eq 0 ]"
pycheck "$tmp/compare.json" <<'PY'
import json, sys
c = json.load(open(sys.argv[1]))
bad = []
for topic, r in c.items():
    print(f"{topic}: {r['replayed']} of {r['original']} replayed, in order {r['inOrder']}, pace {r['pace']:.3f}x "
          f"({r['originalSpanS']:.2f} s of recording in {r['replaySpanS']:.2f} s)")
    # The replay's recorder may join a moment late and its first samples come while discovery settles.
    if not r["inOrder"] or r["replayed"] < 0.95 * r["original"] or not 1.9 <= r["pace"] <= 2.1:
        bad.append(topic)
sys.exit(1 if bad else 0)
PY

# --- A replay steered from a console: pause, seek while paused, resume ---------------------
"$replay" play "$tmp/session.mcap" --station replay-ctl --domain "$domain" --no-keys > "$tmp/play-ctl.log" 2>&1 & player=$!; pids+=($player)
wait_for "playing" "$tmp/play-ctl.log"
sleep 1
"$ctl" pause --station replay-ctl --domain "$domain" > "$tmp/steer.log" 2>&1; rc_pause=$?
"$ctl" show --station replay-ctl --domain "$domain" > "$tmp/show-paused.log" 2>&1
"$ctl" seek 5 --station replay-ctl --domain "$domain" >> "$tmp/steer.log" 2>&1; rc_seek=$?
"$ctl" resume --station replay-ctl --domain "$domain" >> "$tmp/steer.log" 2>&1; rc_resume=$?
sleep 1.5  # a status line or two from where it was sought
"$ctl" seek 99999 --station replay-ctl --domain "$domain" >> "$tmp/steer.log" 2>&1
wait "$player"; rc_player=$?
cat "$tmp/steer.log"; tail -4 "$tmp/play-ctl.log"
check "the replay was paused (rc $rc_pause) and showed it" "[ $rc_pause -eq 0 ] && grep -q 'scene liver: paused' '$tmp/show-paused.log'"
check "it sought while paused (rc $rc_seek) and resumed (rc $rc_resume) from there" \
  "[ $rc_seek -eq 0 ] && [ $rc_resume -eq 0 ] && grep -q 'replay sought to 5.0 s' '$tmp/steer.log' && grep -qE '^viscera-replay: [5-9]\.[0-9] s of' '$tmp/play-ctl.log'"
check "a seek past the end ends the replay (rc $rc_player)" "[ $rc_player -eq 0 ] && grep -q 'published' '$tmp/play-ctl.log'"

# --- Re-simulation in lockstep ---------------------------------------------------------------
"$replay" resimulate "$tmp/session.mcap" --domain "$domain" --report "$tmp/resim.json" --quiet > "$tmp/resim.log" 2>&1; rc_resim=$?
cat "$tmp/resim.log"
check "the re-simulation is bit-identical (rc $rc_resim)" "[ $rc_resim -eq 0 ]"
pycheck "$tmp/resim.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
f, e, m = r["forces"], r["events"], r["frames"]
print(f"resimulate: identical {r['identical']}: {f['identical']}/{f['recorded']} forces, {e['identical']}/{e['recorded']} events, "
      f"{m['identical']}/{m['recorded']} frames over {r['ticks']['run']} ticks; notes {r['notes']}")
ok = r["identical"] and f["recorded"] > 4000 and m["recorded"] > 150 and e["recorded"] >= 5
ok = ok and f["identical"] == f["recorded"] and m["identical"] == m["recorded"] and e["identical"] == e["recorded"]
sys.exit(0 if ok else 1)
PY
# On a domain other than the recording's: the lockstep server follows the driver's --domain (it
# started on the recording's, ran 0 ticks and waited for ever).
other=$(( domain % 200 + 1 ))
"$replay" resimulate "$tmp/session.mcap" --domain "$other" --quiet > "$tmp/resim-other.log" 2>&1; rc_other=$?
check "re-simulated on domain $other, not the recording's $domain (rc $rc_other)" "[ $rc_other -eq 0 ]"
# Stopped: SIGINT ends it within 2 s with its lockstep server and its folder; after a SIGKILL (which
# runs nothing of it) its server dies with it, and the next run removes the folder it left.
resim_tmp="$tmp/resim-tmp"; mkdir -p "$resim_tmp"
lockstep_servers() { pgrep -f -- "--scene-dir $resim_tmp" | wc -l; }
resim_started() { for _ in $(seq 300); do grep -q "tick [0-9]* of" "$tmp/resim-$1.log" 2>/dev/null && return 0; sleep 0.1; done; return 1; }
TMPDIR="$resim_tmp" "$replay" resimulate "$tmp/session.mcap" --domain "$domain" > "$tmp/resim-int.log" 2>&1 & resim=$!
resim_started int
t0=$(date +%s.%N); kill -INT "$resim"; wait "$resim"; rc_int=$?; t1=$(date +%s.%N)
sleep 0.5
check "SIGINT stops a re-simulation (rc $rc_int, 130) within 2 s, saying so" \
  "[ $rc_int -eq 130 ] && python3 -c 'import sys; sys.exit(not $t1 - $t0 < 2)' && grep -q 'interrupted' '$tmp/resim-int.log'"
check "... with its lockstep server and its folder" "[ \$(lockstep_servers) -eq 0 ] && [ -z \"\$(ls -A '$resim_tmp')\" ]"
TMPDIR="$resim_tmp" "$replay" resimulate "$tmp/session.mcap" --domain "$domain" > "$tmp/resim-kill.log" 2>&1 & resim=$!
resim_started kill
kill -KILL "$resim"; wait "$resim" 2>/dev/null
# It is killed with its driver (PR_SET_PDEATHSIG).
for _ in $(seq 50); do [ "$(lockstep_servers)" -eq 0 ] && break; sleep 0.1; done
pgrep -af -- "--scene-dir $resim_tmp" | sed 's/^/still running: /'
check "after a SIGKILL the lockstep server has stopped too, within 5 s" "[ \$(lockstep_servers) -eq 0 ]"
check "... and left its folder" "[ -n \"\$(ls -A '$resim_tmp')\" ]"
TMPDIR="$resim_tmp" "$replay" resimulate "$tmp/session.mcap" --domain "$domain" --scene "$tmp/no-such-scene.json" --quiet > /dev/null 2>&1
check "the next run removed the folder of the killed one" "[ -z \"\$(ls -A '$resim_tmp')\" ]"
# What if the liver were stiffer: the same session, another material; the first divergence named.
sed 's/"youngs_modulus_pa": 5000/"youngs_modulus_pa": 5200/' "$src/data/materials/liver-viscoelastic.json" > "$tmp/stiffer.json"
sed "s#\"material\": \"[^\"]*\"#\"material\": \"$tmp/stiffer.json\"#" "$scene" > "$tmp/stiffer-scene.json"
"$replay" resimulate "$tmp/session.mcap" --domain "$domain" --scene "$tmp/stiffer-scene.json" --report "$tmp/whatif.json" --quiet > "$tmp/whatif.log" 2>&1; rc_whatif=$?
cat "$tmp/whatif.log"
check "another material diverges (rc $rc_whatif, want 1)" "[ $rc_whatif -eq 1 ]"
pycheck "$tmp/whatif.json" "$tmp/resim.json" <<'PY'
import json, sys
w, same = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
d = w["first_divergence"]
print("what-if: first divergence", d, "differences:", w.get("what_if"))
ok = d is not None and d["topic"] in ("force_feedback", "mesh_frame") and d["recorded"] != d["recomputed"] and d["field"]
# The stiffer tissue changes nothing before the first contact: the divergence is in the session.
ok = ok and d["tick"] > 0
sys.exit(0 if ok else 1)
PY

# --- Bad recordings: one line naming the file, exit 2, no crash ------------------------------
size=$(stat -c %s "$tmp/session.mcap")
head -c $((size / 2)) "$tmp/session.mcap" > "$tmp/truncated.mcap"
cp "$tmp/session.mcap" "$tmp/corrupt.mcap"
printf '\x55\xaa\x55\xaa\x55\xaa\x55\xaa' | dd of="$tmp/corrupt.mcap" bs=1 seek=$((size / 3)) conv=notrunc status=none
printf 'time_s,strain,stress_pa\n0,0,0\n' > "$tmp/not-mcap.mcap"
python3 - "$tmp/session.mcap" "$tmp/newer.mcap" <<'PY'
import sys
b = bytearray(open(sys.argv[1], "rb").read())
at = b.index(b"schema_version") + len(b"schema_version")  # then the value: u32 length, digits
n = int.from_bytes(b[at:at + 4], "little")
version = int(b[at + 4:at + 4 + n])
newer = str(version + 1).encode()
if len(newer) > n:
    # One digit more (9 -> 10): the byte comes from the "recorder" value, which precedes it in the
    # same metadata record (keys sorted), so the record and every offset in the file stay.
    r = b.index(b"recorder") + len(b"recorder")
    m = int.from_bytes(b[r:r + 4], "little")
    assert r < at and m > 1
    b[r:r + 4] = (m - 1).to_bytes(4, "little")
    del b[r + 4 + m - 1]
    at -= 1
    b[at:at + 4] = len(newer).to_bytes(4, "little")
    b[at + 4:at + 4 + n] = newer
else:
    b[at + 4:at + 4 + n] = newer.rjust(n, b"0")
open(sys.argv[2], "wb").write(b)
PY
sed 's#liver2.msh#liver.msh#' "$scene" > "$tmp/other-organ.json"
bad() {  # NAME WANT COMMAND...: exit 2, one line on stderr containing WANT
  local name="$1" want="$2"; shift 2
  "$@" > "$tmp/bad.out" 2> "$tmp/bad.err"; local rc=$?
  echo "$name: rc $rc: $(cat "$tmp/bad.err")"
  check "$name: exit 2 and one line naming '$want'" "[ $rc -eq 2 ] && [ \$(wc -l < '$tmp/bad.err') -eq 1 ] && grep -qF -- '$want' '$tmp/bad.err'"
}
bad "truncated, replayed" "truncated.mcap" "$replay" play "$tmp/truncated.mcap" --domain "$domain" --no-keys --quiet
bad "truncated, info" "recover" "$rec" info "$tmp/truncated.mcap"
bad "corrupt, re-simulated" "corrupt.mcap" "$replay" resimulate "$tmp/corrupt.mcap" --domain "$domain" --quiet
bad "not MCAP" "not-mcap.mcap" "$replay" resimulate "$tmp/not-mcap.mcap" --domain "$domain" --quiet
bad "newer schema" "newer viscera" "$replay" play "$tmp/newer.mcap" --domain "$domain" --no-keys --quiet
bad "another organ's scene" "other-organ.json" "$replay" resimulate "$tmp/session.mcap" --domain "$domain" --scene "$tmp/other-organ.json" --quiet
bad "recover onto itself" "another file" "$rec" recover "$tmp/killed.mcap" "$tmp/killed.mcap"
bad "play from past the end" "is past the recording" "$replay" play "$tmp/session.mcap" --from 1000 --station x --domain "$domain" --no-keys --quiet
echo '[1, 2]' > "$tmp/array-scene.json"
bad "a scene that is an array" "array-scene.json: JSON: [1,2] is not an object" "$replay" resimulate "$tmp/session.mcap" --domain "$domain" --scene "$tmp/array-scene.json" --quiet

# --- Damage: recover keeps what is intact and says what was lost; info --verify judges the same --
python3 - "$tmp/session.mcap" "$tmp" <<'PY'
import sys
b = open(sys.argv[1], "rb").read()
def save(name, data): open(f"{sys.argv[2]}/{name}", "wb").write(data)
def first(opcode):  # the offset of the first record with that opcode: walk the records after the magic
    at = 8
    while b[at] != opcode:
        at += 9 + int.from_bytes(b[at + 1:at + 9], "little")
    return at
a = first(9) + 9 + 16  # an attachment: opcode, length, two times, then its name, media type, data length, data
for _ in range(2):
    a += 4 + int.from_bytes(b[a:a + 4], "little")
i = a + 8  # its data, which its u64 length precedes
flip = bytearray(b); flip[i + 10] ^= 1; save("att-flip.mcap", flip)
huge = bytearray(b); n = int.from_bytes(b[i - 8:i], "little"); huge[i - 8:i] = (n + 2**40).to_bytes(8, "little"); save("att-huge.mcap", huge)
at = first(6)  # the first chunk
length = int.from_bytes(b[at + 1:at + 9], "little")
chunk = bytearray(b); chunk[at + 9 + length // 2] ^= 0x40; save("chunk-flip.mcap", chunk)
PY
for f in att-flip att-huge chunk-flip; do
  "$rec" info "$tmp/$f.mcap" --verify > "$tmp/$f.info" 2>&1; rc=$?
  check "info --verify finds $f (rc $rc, want 1)" "[ $rc -eq 1 ] && grep -q 'damaged:' '$tmp/$f.info'"
done
grep -A2 "records:" "$tmp/att-huge.info"
"$rec" recover "$tmp/chunk-flip.mcap" "$tmp/chunk-fixed.mcap" > "$tmp/chunk-fixed.log" 2>&1; rc_fix=$?; cat "$tmp/chunk-fixed.log"
node "$node_dir/check_mcap.mjs" "$tmp/chunk-fixed.mcap" > "$tmp/chunk-fixed.json"; rc_fixed_official=$?
check "recover of a damaged first chunk exits 1 naming the loss, the official reader accepts the copy (rc $rc_fix, $rc_fixed_official)" \
  "[ $rc_fix -eq 1 ] && grep -q 'lost bytes' '$tmp/chunk-fixed.log' && [ $rc_fixed_official -eq 0 ]"
pycheck "$tmp/chunk-fixed.json" "$tmp/official.json" <<'PY'
import json, sys
fixed, whole = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
n, total = fixed["statistics"]["messageCount"], whole["statistics"]["messageCount"]
print(f"a damaged first chunk: {n} of {total} messages recovered, {len(fixed['attachments'])} attachments")
sys.exit(0 if 0.5 * total < n < total and len(fixed["attachments"]) == len(whole["attachments"]) else 1)
PY

# --- A replay never drives a live server ------------------------------------------------------
"$build/server/runtime/viscera-server" --scene "$scene" --station live-guard > "$tmp/guard-server.log" 2>&1 & guard=$!; pids+=($guard)
wait_for "DDS domain" "$tmp/guard-server.log"
bad "a replay into a live server's partition" "holds a live viscera-server" "$replay" play "$tmp/session.mcap" --station live-guard --domain "$domain" --no-keys --quiet
bad "a replay into every partition" "holds a DDS wildcard" "$replay" play "$tmp/session.mcap" --station '*' --domain "$domain" --no-keys --quiet
"$ctl" show --station live-guard --domain "$domain" > "$tmp/guard-show.log" 2>&1
check "the live server's instruments stay free" "grep -q 'instruments: 1 (probe, free)' '$tmp/guard-show.log'"
# A server that starts in a replay's partition stops the replay.
"$replay" play "$tmp/session.mcap" --loop --station late-guard --domain "$domain" --no-keys --quiet > "$tmp/late.log" 2>&1 & late=$!; pids+=($late)
sleep 1.5
"$build/server/runtime/viscera-server" --scene "$scene" --station late-guard > "$tmp/late-server.log" 2>&1 & late_server=$!; pids+=($late_server)
for _ in $(seq 150); do kill -0 "$late" 2>/dev/null || break; sleep 0.1; done
wait "$late"; rc_late=$?
cat "$tmp/late.log"
check "a server joining the replay's partition stops it (rc $rc_late, want 3)" "[ $rc_late -eq 3 ] && grep -q 'holds a live viscera-server' '$tmp/late.log'"
kill -INT "$guard" "$late_server"; wait "$guard" "$late_server"

finish
