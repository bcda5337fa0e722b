#!/usr/bin/env bash
# Several hosts on one machine: three network namespaces joined by veth pairs to a bridge in a
# fourth, with addresses from 198.18.0.0/15 (reserved for network tests) that exist only on those
# links. The server runs in one, a haptic client in a second, the recorder in a third, each with
# deploy/dds/lan.xml, its own interface and the three hosts as unicast peers (no multicast, no
# loopback between them). Discovery must work across the links, the press must produce forces,
# and the recording must hold every message. Everything made is removed at the end, also when
# the test fails. Needs root (ip netns); where namespaces cannot be made it says so and skips.
# Usage: namespaces_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
tag=$(( $$ % 10000 ))
bridge="vb$tag"; hosts=(s h r)  # server, haptic client, recorder
net="198.18.$(( RANDOM % 250 + 1 ))"
pids=()
cleanup() {
  kill "${pids[@]}" 2>/dev/null; wait "${pids[@]}" 2>/dev/null
  for h in "${hosts[@]}"; do ip netns del "v$tag$h" 2>/dev/null; done
  ip netns del "$bridge" 2>/dev/null
  rm -rf "$tmp"
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
for h in "${hosts[@]}"; do
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
set +e
peers="$net.1,$net.2,$net.3"
# The prefix that runs a command as host s, h or r (number 1, 2, 3), with lan.xml on its own link.
# ip and env exec the program: started in the background, $! is the program itself.
s=(ip netns exec "v${tag}s" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.1" VISCERA_DDS_PEERS="$peers")
h=(ip netns exec "v${tag}h" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.2" VISCERA_DDS_PEERS="$peers")
r=(ip netns exec "v${tag}r" env CYCLONEDDS_URI="file://$src/deploy/dds/lan.xml" VISCERA_DDS_INTERFACE="$net.3" VISCERA_DDS_PEERS="$peers")
# Each host has its loopback and its one link: the processes can meet only across the bridge.
check "the client's host has only its own loopback and its link ($(ip netns exec "v${tag}h" ip -4 -o addr | awk '{print $4}' | xargs))" \
  "[ \"\$(ip netns exec v${tag}h ip -4 -o addr | awk '{print \$4}' | xargs)\" = '127.0.0.1/8 $net.2/24' ]"

"${s[@]}" "$build/server/runtime/viscera-server" --scene "$scene" --station bay-1 > "$tmp/server.log" 2>&1 &
pids+=($!)
wait_for "station bay-1" "$tmp/server.log" 100
"${r[@]}" "$build/tools/viscera-record/viscera-record" --domain "$domain" --station bay-1 --out "$tmp/lan.mcap" --duration 9 > "$tmp/rec.log" 2>&1 &
recorder=$!; pids+=($recorder)
sleep 1
"${h[@]}" "$build/tools/haptic-client/haptic-client" --domain "$domain" --station bay-1 --client-id 11 --duration 4 --quiet --report "$tmp/hc.json" > "$tmp/hc.log" 2>&1
rc_hc=$?
wait "$recorder"; rc_rec=$?
cat "$tmp/hc.log" "$tmp/rec.log"
check "the haptic client in its own namespace found the server in another and pressed (rc $rc_hc)" \
  "[ $rc_hc -eq 0 ] && grep -q 'contact at' '$tmp/hc.log'"
check "the recorder in a third namespace recorded the session (rc $rc_rec)" "[ $rc_rec -eq 0 ] && grep -q 'wrote' '$tmp/rec.log'"
check "the recording has every message: no writer has a gap" \
  "grep -q 'writer .* (instrument_command)' '$tmp/rec.log' && grep -q 'writer .* (force_feedback)' '$tmp/rec.log' && ! grep 'writer ' '$tmp/rec.log' | grep -qv ' 0 missing in 0 gaps'"
pycheck "$tmp/hc.json" "$tmp/rec.log" <<'PY'
import json, re, sys
r = json.load(open(sys.argv[1]))
log = open(sys.argv[2]).read()
commands = int(re.findall(r"commands (\d+)", log)[-1])
forces = int(re.findall(r"forces (\d+)", log)[-1])
rt = r["round_trip_us"]
print(f"[ figure ] three namespaces over a bridge: round trip p50 {rt['p50']:.0f} us p99 {rt['p99']:.0f} us; "
      f"recorded {commands} commands and {forces} forces")
# The client sends one command a millisecond for 4 s; each is answered at once (and the ticks add theirs).
sys.exit(0 if commands >= 3500 and forces >= commands else 1)
PY
kill -INT "${pids[0]}"; wait "${pids[0]}"; rc_server=$?
check "the server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"
echo "namespaces_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
