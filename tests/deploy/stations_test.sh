#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Several stations on one DDS domain and one machine: three servers (the 1.5k liver) in stations
# bay-1, bay-2 and bay-3, scripted haptic clients in bay-1 and bay-2 under the same client id and
# instrument (each station's ids are its own), nothing in bay-3, and one console watching all
# three. Each client moves only its own station's organ: bay-3's server never has an instrument in
# use nor a force. Reports what one machine holds: each server's physics rate and late ticks, and
# each client's round trip.
# Usage: stations_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
server="$build/server/runtime/viscera-server"; hc="$build/tools/haptic-client/haptic-client"
for b in 1 2 3; do
  "$server" --scene "$scene" --station "bay-$b" > "$tmp/server-$b.log" 2>&1 &
  pids+=($!)
done
for b in 1 2 3; do wait_for "station bay-$b" "$tmp/server-$b.log" 150; done
openssl rand -hex 16 > "$tmp/token"; chmod 600 "$tmp/token"
"$build/tools/viscera-console/viscera-console" --domain "$domain" --stations bay-1,bay-2,bay-3 --listen 127.0.0.1:0 --token-file "$tmp/token" > "$tmp/console.log" 2>&1 &
console=$!; pids+=($console)
wait_for "station(s); open" "$tmp/console.log" 100
url="$(grep -o 'http://[^ ]*' "$tmp/console.log" | head -1)?token=$(cat "$tmp/token")"
for b in 1 2; do
  "$hc" --domain "$domain" --station "bay-$b" --client-id 11 --instrument 1 --duration 6 --quiet --report "$tmp/hc-$b.json" > "$tmp/hc-$b.log" 2>&1 &
  clients[$b]=$!
done
sleep 3
curl -s "${url/\/?token=/\/stats?token=}" > "$tmp/stats.json"; rc_stats=$?
wait "${clients[1]}"; rc1=$?
wait "${clients[2]}"; rc2=$?
for k in 0 1 2; do kill -INT "${pids[$k]}"; done
for k in 0 1 2; do wait "${pids[$k]}"; done
kill "$console"; wait "$console" 2>/dev/null
cat "$tmp/hc-1.log" "$tmp/hc-2.log"
check "bay-1's client claimed instrument 1 and pressed (rc $rc1)" "[ $rc1 -eq 0 ] && grep -q 'contact at' '$tmp/hc-1.log'"
check "bay-2's client, same client id and instrument, did too (rc $rc2)" "[ $rc2 -eq 0 ] && grep -q 'contact at' '$tmp/hc-2.log'"
check "bay-1's and bay-2's servers each saw their one client" \
  "grep -q '1 instruments in use' '$tmp/server-1.log' && grep -q '1 instruments in use' '$tmp/server-2.log'"
check "bay-3's server never had an instrument in use nor a force" \
  "! grep -q '[1-9] instruments in use' '$tmp/server-3.log' && ! grep 'Hz physics' '$tmp/server-3.log' | grep -qv '|F| 0.000 N'"
check "one console watched all three stations (/stats, rc $rc_stats)" \
  "python3 -c \"import json,sys; s=json.load(open('$tmp/stats.json')); sys.exit(sorted(x['name'] for x in s['stations']) != ['bay-1','bay-2','bay-3'])\""
pycheck "$tmp" <<'PY'
import json, re, sys
d = sys.argv[1]
for b in (1, 2, 3):
    log = open(f"{d}/server-{b}.log").read()
    rates = [float(x) for x in re.findall(r"(\d+) Hz physics", log)][1:]  # the first second starts up
    stop = re.search(r"stopped after (\d+) ticks, (\d+) late, (\d+) missed slots", log)
    line = f"[ figure ] bay-{b}: physics {min(rates):.0f}-{max(rates):.0f} Hz, {stop.group(2)} of {stop.group(1)} ticks late, {stop.group(3)} slots missed"
    if b < 3:
        rt = json.load(open(f"{d}/hc-{b}.json"))["round_trip_us"]
        line += f"; its client's round trip p50 {rt['p50']:.0f} us p99 {rt['p99']:.0f} us"
    print(line)
sys.exit(0)
PY
finish
