#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain on loopback: two clients with two
# instruments at once; a hostile publisher's garbage, truncated, wrong-schema, NaN and not-owned
# payloads are rejected and counted while the good clients keep their 1 kHz force stream; a client
# killed with SIGKILL loses its instrument within the lease (another client can then claim it);
# another process pauses the simulation mid-press, resets the organ while paused and resumes it.
# Usage: sessions_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
trap 'kill "$server" "$victim" "$watcher" 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
watcher=
hc="$build/tools/haptic-client/haptic-client"
"$build/server/runtime/viscera-server" --scene "$scene" > "$tmp/server.log" 2>&1 &
server=$!
# Two clients, two instruments, plus hostile traffic, all at once.
"$hc" --domain "$domain" --client-id 11 --instrument 1 --duration 3 --report "$tmp/a.json" > "$tmp/a.log" 2>&1 &
a=$!
"$hc" --domain "$domain" --client-id 12 --instrument 2 --duration 3 --depth 0.01 --report "$tmp/b.json" > "$tmp/b.log" 2>&1 &
b=$!
"$build/tests/integration/hostile_publisher" "$domain" 3 > "$tmp/hostile.log" 2>&1
wait $a; rc_a=$?
wait $b; rc_b=$?
# A client that claims instrument 1 and is then killed with SIGKILL.
"$hc" --domain "$domain" --client-id 21 --instrument 1 --duration 30 > "$tmp/victim.log" 2>&1 &
victim=$!
for _ in $(seq 50); do grep -q "claimed" "$tmp/victim.log" && break; sleep 0.1; done
kill -KILL "$victim"; killed_at=$(date +%s.%N)
# Another client must get instrument 1 within the lease (0.5 s) plus discovery slack.
"$hc" --domain "$domain" --client-id 22 --instrument 1 --duration 0.5 > "$tmp/heir.log" 2>&1
rc_heir=$?; claimed_at=$(date +%s.%N)
# Session control from another process (an instructor): pause mid-press, reset while paused, resume.
ctl="$build/tools/viscera-control/viscera-control"
"$ctl" events --domain "$domain" --client-id 902 --duration 60 > "$tmp/events.log" 2>&1 &
watcher=$!
for _ in $(seq 100); do grep -q "following the events" "$tmp/events.log" && break; sleep 0.05; done
"$hc" --domain "$domain" --client-id 31 --instrument 2 --duration 12 --depth 0.02 --watch-mesh --quiet --report "$tmp/ctl.json" > "$tmp/ctl.log" 2>&1 &
presser=$!
for _ in $(seq 100); do grep -q "contact at" "$tmp/ctl.log" && break; sleep 0.05; done
sleep 2
"$ctl" pause --domain "$domain" > "$tmp/control.log" 2>&1; rc_pause=$?
sleep 0.8
"$ctl" reset --domain "$domain" >> "$tmp/control.log" 2>&1; rc_reset=$?
sleep 0.8
"$ctl" annotate "resected segment IV" --domain "$domain" --client-id 901 >> "$tmp/control.log" 2>&1; rc_note=$?
"$ctl" resume --domain "$domain" >> "$tmp/control.log" 2>&1; rc_resume=$?
wait $presser; rc_presser=$?
sleep 0.5; kill "$watcher"; wait "$watcher" 2>/dev/null
# Two runs under one client id: the second cannot claim what the first holds, and a release sent
# under that id by another participant (the hostile publisher) is refused: the server binds a client
# id to the DDS participant that acts on instruments under it (schema 13). The first run keeps its
# instrument to its end.
"$hc" --domain "$domain" --client-id 7 --instrument 2 --duration 8 --depth 0.01 --quiet --report "$tmp/twin-a.json" > "$tmp/twin-a.log" 2>&1 &
twin_a=$!
for _ in $(seq 100); do grep -q "claimed" "$tmp/twin-a.log" && break; sleep 0.05; done
"$hc" --domain "$domain" --client-id 7 --instrument 2 --duration 1 --quiet > "$tmp/twin-b.log" 2>&1; rc_twin_b=$?
"$build/tests/integration/hostile_publisher" "$domain" release 2 7 > "$tmp/twin-release.log" 2>&1
wait "$twin_a"; rc_twin_a=$?
cat "$tmp/twin-b.log" "$tmp/twin-a.log"
check "a second run under one client id is refused its claim (rc $rc_twin_b)" \
  "[ $rc_twin_b -eq 3 ] && grep -q 'held under this client id (7) by another client' '$tmp/twin-b.log'"
check "another participant's release under the first run's id is refused: it keeps its instrument to its end (rc $rc_twin_a)" \
  "[ $rc_twin_a -eq 0 ] && ! grep -q 'no longer this client' '$tmp/twin-a.log'"
# A second run under one id whose first run ends within its claim timeout claims the instrument
# then, and drives it: the first run's answers (higher sequence numbers, same id) no longer hide
# its own (it drove the tip to -6 cm with 0 N, 32 of 2,000 round trips answered).
"$hc" --domain "$domain" --client-id 71 --instrument 2 --duration 3 --depth 0.01 --quiet > "$tmp/twin-c.log" 2>&1 &
twin_c=$!
for _ in $(seq 100); do grep -q "claimed" "$tmp/twin-c.log" && break; sleep 0.05; done
"$hc" --domain "$domain" --client-id 71 --instrument 2 --duration 2 --depth 0.01 --quiet --report "$tmp/twin-d.json" > "$tmp/twin-d.log" 2>&1
rc_twin_d=$?
wait "$twin_c"
check "a second run under one id claims the instrument once the first lets it go (rc $rc_twin_d)" "[ $rc_twin_d -eq 0 ]"
pycheck "$tmp/twin-d.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
answered, periods = r["round_trip_us"]["samples"], len(r["samples"])
touched = [s for s in r["samples"] if s["in_contact"]]
print(f"[ figure ] the second run under one id: {answered} of {periods} commands answered, {len(touched)} periods in contact")
assert answered > 0.5 * periods, f"only {answered} of {periods} commands answered (the bug answered 32 of 2,000)"
assert touched and max(s["force_n"][2] for s in touched) > 0.05, "it never pressed the tissue"
PY
kill -INT "$server"; wait "$server"; rc_server=$?
cat "$tmp/control.log" "$tmp/ctl.log" "$tmp/events.log"
check "annotation sent (rc $rc_note)" "[ $rc_note -eq 0 ]"
pycheck "$tmp/events.log" <<'PY'
import sys
lines = [l.split() for l in open(sys.argv[1]) if l.startswith("event ")]
kinds = [l[1] for l in lines]
def first(kind, **want):
    for i, l in enumerate(lines):
        if l[1] == kind and all(l[l.index(k) + 1].rstrip(":") == str(v) for k, v in want.items()):
            return i
    raise AssertionError(f"no {kind} {want} among the events: {kinds}")
claimed = first("instrument_claimed", instrument=2, client=31)
touched = first("contact_started", instrument=2, client=31)
paused, reset, note, resumed = first("paused", client=900), first("organ_reset", client=900), first("annotation", client=901), first("resumed", client=900)
released = first("instrument_released", instrument=2, client=31)
assert claimed < touched < paused < reset < note < resumed < released, f"events out of order: {kinds}"
assert "resected segment IV" in open(sys.argv[1]).read()
print(f"[ figure ] events seen by a console: {len(lines)}, in order: claimed, contact_started, paused, organ_reset, annotation, resumed, released")
PY
check "pause, reset, resume accepted (rc $rc_pause $rc_reset $rc_resume)" "[ $rc_pause -eq 0 ] && [ $rc_reset -eq 0 ] && [ $rc_resume -eq 0 ]"
check "pausing client ran (rc $rc_presser)" "[ $rc_presser -eq 0 ]"
check "control reports the paused scene" "grep -q 'scene liver: paused' '$tmp/control.log'"
check "server logged the reset" "grep -q 'reset the organ to rest' '$tmp/server.log'"
pycheck "$tmp/ctl.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
frames = sorted(r["mesh"]["samples"], key=lambda f: f["t_s"])
# The pause: the longest run of frames whose simulated time does not advance.
best, start = (0, 0), 0
for i in range(1, len(frames) + 1):
    if i == len(frames) or frames[i]["sim_time_s"] != frames[start]["sim_time_s"]:
        if i - start > best[1] - best[0]: best = (start, i)
        start = i
held = frames[best[0]:best[1]]
t0, t1 = held[0]["t_s"], held[-1]["t_s"]
assert t1 - t0 > 1.2, f"simulated time stood still for only {t1 - t0:.2f} s (pause to resume takes at least 1.6 s)"
before = [f for f in held if f["t_s"] < t0 + 0.5]
after = [f for f in held if f["t_s"] > t1 - 0.5]
assert min(f["max_displacement_m"] for f in before) > 0.003, "the paused organ was not pressed in"
assert max(f["max_displacement_m"] for f in after) < 0.0005, "reset did not put the organ back at rest"
later = [f for f in frames if f["t_s"] > t1 + 0.5]
assert later and later[-1]["sim_time_s"] > held[0]["sim_time_s"] + 0.3, "simulated time did not resume"
forces = [x for x in r["samples"] if t0 < x["t_s"] < t1]
rate = len(forces) / (t1 - t0)
assert rate > 800, f"forces at {rate:.0f}/s while paused"
print(f"[ figure ] session control: paused for {t1 - t0:.2f} s (simulated time held at {held[0]['sim_time_s']:.3f} s), "
      f"surface displaced {1000 * min(f['max_displacement_m'] for f in before):.1f} mm before the reset, "
      f"{1000 * max(f['max_displacement_m'] for f in after):.2f} mm after; forces still answered at {rate:.0f}/s")
PY
cat "$tmp/a.log" "$tmp/b.log" "$tmp/hostile.log" "$tmp/victim.log" "$tmp/heir.log" "$tmp/server.log"
check "client A ran (rc $rc_a)" "[ $rc_a -eq 0 ]"
check "client B ran (rc $rc_b)" "[ $rc_b -eq 0 ]"
check "victim had claimed instrument 1" "grep -q claimed '$tmp/victim.log'"
check "the killed client's instrument was released and claimed by another (rc $rc_heir)" "[ $rc_heir -eq 0 ]"
check "server logged the release" "grep -q 'instrument 1 released' '$tmp/server.log'"
check "server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"
rejected=$(sed -n 's/.* \([0-9]*\) messages rejected.*/\1/p' "$tmp/server.log" | tail -1)
check "server rejected and counted hostile payloads ($rejected)" "[ -n '$rejected' ] && [ '$rejected' -gt 1000 ]"
# Counted by reason: the hostile publisher sends all three kinds (4 malformed, 1 not owned, 1 unknown
# instrument per round), and one release under another participant's client id (above).
reasons=$(grep 'stopped after' "$tmp/server.log" | grep -o "malformed [0-9]*, not owner [0-9]*, unknown instrument [0-9]*, another participant's client id [0-9]*" | tr -d "'")
echo "[ figure ] rejected by reason: $reasons"
check "rejections counted by reason ($reasons)" "python3 -c \"import re,sys; m,o,u,p=map(int,re.findall(r'\\d+','$reasons')); sys.exit(not (m > 3*o > 0 and u > 0 and p >= 1 and m + o + u + p == $rejected))\""
pycheck "$tmp/a.json" "$tmp/b.json" "$(python3 -c "print($claimed_at - $killed_at)")" <<'PY'
import json, sys
for path in sys.argv[1:3]:
    r = json.load(open(path))
    rate = len(r["samples"]) / r["duration_s"]
    assert rate > 800, f"{path}: force stream at {rate:.0f} Hz under hostile traffic"
    print(f"[ figure ] client {r['client_id']} instrument {r['instrument']}: {rate:.0f} forces/s under hostile traffic, "
          f"round trip p50 {r['round_trip_us']['p50']:.0f} us p99 {r['round_trip_us']['p99']:.0f} us")
print(f"[ figure ] SIGKILLed client's instrument claimed by another {float(sys.argv[3]):.2f} s after the kill")
PY
finish
