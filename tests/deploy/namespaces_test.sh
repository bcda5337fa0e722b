#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Several hosts on one machine: three network namespaces joined by veth pairs to a bridge in a
# fourth, with addresses from 198.18.0.0/15 (reserved for network tests) that exist only on those
# links. The server runs in one, a haptic client in a second, the recorder in a third, each with
# deploy/dds/lan.xml, its own interface and the three hosts as unicast peers (no multicast, no
# loopback between them). Discovery must work across the links, the press must produce forces,
# and the recording must hold every message. Everything made is removed at the end, also when
# the test fails. Needs root (ip netns); where namespaces cannot be made it says so and skips.
# A fourth host's link is slow and lossy: 2 ms of delay and 1% loss each way, from a relay in user
# space (tests/deploy/link_relay.py: the kernel has no netem); a second haptic client presses over
# it, and the test reports what it feels (round trip, how often the device rendered the local force
# model of an older command) beside the first client's clean link.
# Usage: namespaces_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
tag=$(( $$ % 10000 ))
bridge="vb$tag"; hosts=(s h r l)  # server, haptic client, recorder, haptic client behind the slow link
net="198.18.$(( RANDOM % 250 + 1 ))"
pids=(); relays=()
cleanup() {
  # Each step may fail (a process gone, a namespace never made); under set -e that must not stop
  # the rest (tests/lint/exit_traps.py).
  kill "${relays[@]}" 2>/dev/null || true; wait "${relays[@]}" 2>/dev/null || true
  kill "${pids[@]}" 2>/dev/null || true; wait "${pids[@]}" 2>/dev/null || true
  for h in "${hosts[@]}"; do ip netns del "v$tag$h" 2>/dev/null || true; done
  ip netns del "$bridge" 2>/dev/null || true
  show_output; rm -rf "$tmp"
}
trap cleanup EXIT
if [ "$(id -u)" -ne 0 ] || ! command -v ip >/dev/null || ! ip netns add "$bridge" 2>"$tmp/netns.err"; then
  echo "namespaces_test: SKIPPED every case (several hosts in network namespaces): cannot create a network namespace here" \
    "(needs root and iproute2): $(cat "$tmp/netns.err" 2>/dev/null)"
  exit 0
fi
set -e
ip netns exec "$bridge" ip link add br0 type bridge
ip netns exec "$bridge" ip link set br0 up
k=1
for h in s h r; do
  ns="v$tag$h"
  ip netns add "$ns"
  ip link add "v$tag${h}0" type veth peer name "v$tag${h}1"
  ip link set "v$tag${h}0" netns "$ns"
  ip link set "v$tag${h}1" netns "$bridge"
  ip netns exec "$ns" ip addr add "$net.$k/24" dev "v$tag${h}0"
  ip netns exec "$ns" ip link set "v$tag${h}0" up
  ip netns exec "$ns" ip link set lo up
  ip netns exec "$bridge" ip link set "v$tag${h}1" master br0
  ip netns exec "$bridge" ip link set "v$tag${h}1" up
  k=$((k + 1))
done
# Host l: its link is the relay's two TAP devices, one in its namespace, one on the bridge.
ip netns add "v${tag}l"
ip netns exec "v${tag}l" python3 "$src/tests/deploy/link_relay.py" "t${tag}l" "$tmp/link.sock" --listen --delay-ms 2 --loss 0.01 --seed 7 > "$tmp/relay-l.log" 2>&1 &
relays+=($!)
ip netns exec "$bridge" python3 "$src/tests/deploy/link_relay.py" "t${tag}b" "$tmp/link.sock" --connect --delay-ms 2 --loss 0.01 --seed 8 > "$tmp/relay-b.log" 2>&1 &
relays+=($!)
set +e
wait_for "linked" "$tmp/relay-l.log" 50 && wait_for "linked" "$tmp/relay-b.log" 50 || exit 1
set -e  # the bridge's side first: frames from host l then find it up
ip netns exec "$bridge" ip link set "t${tag}b" master br0
ip netns exec "$bridge" ip link set "t${tag}b" up
ip netns exec "v${tag}l" ip addr add "$net.4/24" dev "t${tag}l"
ip netns exec "v${tag}l" ip link set "t${tag}l" up
ip netns exec "v${tag}l" ip link set lo up
set +e
peers="$net.1,$net.2,$net.3,$net.4"
# The prefix that runs a command as host s, h or r (number 1, 2, 3), with lan.xml on its own link.
# ip and env exec the program: started in the background, $! is the program itself.
s=(ip netns exec "v${tag}s" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.1" VISCERA_DDS_PEERS="$peers")
h=(ip netns exec "v${tag}h" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.2" VISCERA_DDS_PEERS="$peers")
r=(ip netns exec "v${tag}r" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.3" VISCERA_DDS_PEERS="$peers")
l=(ip netns exec "v${tag}l" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.4" VISCERA_DDS_PEERS="$peers")
# Each host has its loopback and its one link: the processes can meet only across the bridge.
check "the client's host has only its own loopback and its link ($(ip netns exec "v${tag}h" ip -4 -o addr | awk '{print $4}' | xargs))" \
  "[ \"\$(ip netns exec v${tag}h ip -4 -o addr | awk '{print \$4}' | xargs)\" = '127.0.0.1/8 $net.2/24' ]"

"${s[@]}" "$build/server/runtime/viscera-server" --scene "$scene" --station bay-1 > "$tmp/server.log" 2>&1 &
pids+=($!)
wait_for "station bay-1" "$tmp/server.log" 100
"${r[@]}" "$build/tools/viscera-record/viscera-record" --domain "$domain" --station bay-1 --out "$tmp/lan.mcap" --duration 15 > "$tmp/rec.log" 2>&1 &
recorder=$!; pids+=($recorder)
sleep 1
"${h[@]}" "$build/tools/haptic-client/haptic-client" --domain "$domain" --station bay-1 --client-id 11 --duration 4 --quiet --report "$tmp/hc.json" > "$tmp/hc.log" 2>&1
rc_hc=$?
"${l[@]}" "$build/tools/haptic-client/haptic-client" --domain "$domain" --station bay-1 --client-id 12 --instrument 2 --duration 4 --quiet --report "$tmp/slow.json" > "$tmp/slow.log" 2>&1
rc_slow=$?
wait "$recorder"; rc_rec=$?
kill "${relays[@]}"; wait "${relays[@]}"
cat "$tmp/hc.log" "$tmp/slow.log" "$tmp/rec.log" "$tmp/relay-l.log" "$tmp/relay-b.log"
check "the haptic client in its own namespace found the server in another and pressed (rc $rc_hc)" \
  "[ $rc_hc -eq 0 ] && grep -q 'contact at' '$tmp/hc.log'"
check "a haptic client behind a 2 ms, 1% lossy link pressed (rc $rc_slow)" "[ $rc_slow -eq 0 ] && grep -q 'contact at' '$tmp/slow.log'"
check "the recorder in a third namespace recorded the session (rc $rc_rec)" "[ $rc_rec -eq 0 ] && grep -q 'wrote' '$tmp/rec.log'"
# Every message that crossed the clean links is recorded; the slow client's commands lost on its
# link (1%) reached nobody, the server neither: its command writer alone shows gaps, about 1%.
pycheck "$tmp/rec.log" <<'PY'
import re, sys
writers = re.findall(r"writer \d+ \((\w+)\): (\d+) received, (\d+) missing in (\d+) gaps", open(sys.argv[1]).read())
gappy = [(s, int(r), int(m)) for s, r, m, g in writers if int(m) > 0]
print(f"[ figure ] recorded writers: {len(writers)}; with gaps: {gappy}")
ok = any(s == "instrument_command" for s, _, _, _ in writers) and any(s == "force_feedback" for s, _, _, _ in writers)
ok = ok and len(gappy) <= 1 and all(s == "instrument_command" and m <= 0.03 * (r + m) for s, r, m in gappy)
sys.exit(0 if ok else 1)
PY
pycheck "$tmp/hc.json" "$tmp/slow.json" "$tmp/rec.log" <<'PY'
import json, re, statistics, sys
fast, slow = (json.load(open(f)) for f in sys.argv[1:3])
log = open(sys.argv[3]).read()
commands = int(re.findall(r"commands (\d+)", log)[-1])
forces = int(re.findall(r"forces (\d+)", log)[-1])
def felt(r):
    ages = [s["model_age_commands"] for s in r["samples"] if s["in_contact"]]
    older = sum(a >= 1 for a in ages) / max(1, len(ages))
    return r["round_trip_us"], older, statistics.median(ages) if ages else 0
for name, r in (("clean link", fast), ("2 ms + 1% loss each way", slow)):
    rt, older, age = felt(r)
    print(f"[ figure ] {name}: round trip p50 {rt['p50']:.0f} us p99 {rt['p99']:.0f} us; in contact, {100 * older:.0f}% of rendered "
          f"forces came from the local force model of an older command (median {age:.0f} commands old)")
print(f"[ figure ] recorded {commands} commands and {forces} forces")
# Two clients send one command a millisecond for 4 s each; each is answered at once (the ticks add theirs).
rt_slow = slow["round_trip_us"]
sys.exit(0 if commands >= 7000 and forces >= commands and rt_slow["p50"] >= 4000 else 1)
PY
kill -INT "${pids[0]}"; wait "${pids[0]}"; rc_server=$?
check "the server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"
finish
