#!/usr/bin/env bash
# Integration, separate processes over a real DDS domain on loopback: two clients with two
# instruments at once; a hostile publisher's garbage, truncated, wrong-schema, NaN and not-owned
# payloads are rejected and counted while the good clients keep their 1 kHz force stream; a client
# killed with SIGKILL loses its instrument within the lease (another client can then claim it).
# Usage: sessions_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
trap 'kill "$server" "$victim" 2>/dev/null; rm -rf "$tmp"' EXIT
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
kill -INT "$server"; wait "$server"; rc_server=$?
cat "$tmp/a.log" "$tmp/b.log" "$tmp/hostile.log" "$tmp/victim.log" "$tmp/heir.log" "$tmp/server.log"
check "client A ran (rc $rc_a)" "[ $rc_a -eq 0 ]"
check "client B ran (rc $rc_b)" "[ $rc_b -eq 0 ]"
check "victim had claimed instrument 1" "grep -q claimed '$tmp/victim.log'"
check "the killed client's instrument was released and claimed by another (rc $rc_heir)" "[ $rc_heir -eq 0 ]"
check "server logged the release" "grep -q 'instrument 1 released' '$tmp/server.log'"
check "server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"
rejected=$(sed -n 's/.* \([0-9]*\) messages rejected.*/\1/p' "$tmp/server.log" | tail -1)
check "server rejected and counted hostile payloads ($rejected)" "[ -n '$rejected' ] && [ '$rejected' -gt 1000 ]"
python3 - "$tmp/a.json" "$tmp/b.json" "$(python3 -c "print($claimed_at - $killed_at)")" <<'PY' || failures=$((failures+1))
import json, sys
for path in sys.argv[1:3]:
    r = json.load(open(path))
    rate = len(r["samples"]) / r["duration_s"]
    assert rate > 800, f"{path}: force stream at {rate:.0f} Hz under hostile traffic"
    print(f"[ figure ] client {r['client_id']} instrument {r['instrument']}: {rate:.0f} forces/s under hostile traffic, "
          f"round trip p50 {r['round_trip_us']['p50']:.0f} us p99 {r['round_trip_us']['p99']:.0f} us")
print(f"[ figure ] SIGKILLed client's instrument claimed by another {float(sys.argv[3]):.2f} s after the kill")
PY
[ $? -eq 0 ] && passed=$((passed+1))
echo "sessions_test: $passed passed, $failures failed"
[ "$failures" -eq 0 ]
