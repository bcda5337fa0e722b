#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Integration, separate processes over a real DDS domain and a real browser: viscera-server, a
# scripted haptic client pressing the liver, and viscera-console; the page opened in Debian's
# headless Chromium by playwright-core (tests/node/console_page.mjs: refused without the token, the
# mesh moves, the force plot rises, Pause pauses the server as its scene state says, a bookmark
# reaches the events, the material form changes the tissue), then misbehaving browsers against
# the bridge (tests/node/console_robustness.mjs: a slow one, malformed messages, an oversized one,
# a flood, a wrong token) while a well-behaved one keeps receiving frames; and the reference client
# of the Foxglove WebSocket protocol (tests/node/foxglove_client.mjs); and the session's recording
# opened for replay from the console (tests/node/console_replay.mjs); a second station's server
# found on the domain (--discover). Also the console's refusals of a bad command line and token file.
# Usage: console_test.sh BUILD_DIR SOURCE_DIR    (SHOTS=DIR keeps the page's screenshots)
set -u
build="$1"; src="$2"
. "$(dirname "$0")/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; [ -n "${KEEP:-}" ] && cp -r "$tmp" /tmp/console-test/; show_output; rm -rf "$tmp"' EXIT
console="$build/tools/viscera-console/viscera-console"
node_dir="$src/tests/node"
[ -d "$node_dir/node_modules/playwright-core" ] || { echo "FAIL playwright-core is not installed (deploy/install-deps.sh runs npm ci in tests/node)"; exit 1; }
command -v chromium >/dev/null || { echo "FAIL chromium is not installed (deploy/install-deps.sh installs Debian's chromium)"; exit 1; }

# Refusals before anything runs.
"$console" --help > "$tmp/help.txt"; rc=$?
check "--help" '[ $rc -eq 0 ] && grep -q -- "--token-file" "$tmp/help.txt"'
"$console" --token-file "$tmp/none" > "$tmp/e1.txt" 2>&1; rc=$?
check "a missing token file is named" '[ $rc -eq 2 ] && grep -q "$tmp/none: cannot open file" "$tmp/e1.txt"'
echo short > "$tmp/short"
"$console" --token-file "$tmp/short" > "$tmp/e2.txt" 2>&1; rc=$?
check "a short token is refused" '[ $rc -eq 2 ] && grep -q "short:1: token: has 5 characters (32 to 256" "$tmp/e2.txt"'
# Token files that are not small regular files: refused at once, never read without end.
mkfifo "$tmp/fifo"
head -c 10000000 /dev/zero | tr '\0' 'a' > "$tmp/huge-token"
for f in /dev/zero "$tmp/fifo" "$tmp/huge-token"; do
  timeout 10 "$console" --token-file "$f" > "$tmp/e4.txt" 2>&1; rc=$?
  check "token file $f refused at once (rc $rc: $(head -c 200 "$tmp/e4.txt"))" '[ $rc -eq 2 ] && [ $(wc -l < "$tmp/e4.txt") -eq 1 ]'
done
openssl rand -hex 16 > "$tmp/token"; chmod 600 "$tmp/token"
cp "$tmp/token" "$tmp/loose-token"; chmod 644 "$tmp/loose-token"
timeout 10 "$console" --token-file "$tmp/loose-token" --domain 999 > "$tmp/e5.txt" 2>&1
check "a token file others may read is warned about" 'grep -q "warning viscera-console: .*loose-token (mode 644) may be read by others" "$tmp/e5.txt"'
"$console" --token-file "$tmp/token" --listen 127.0.0.1:99999 > "$tmp/e3.txt" 2>&1; rc=$?
check "a bad --listen is refused" '[ $rc -eq 2 ] && grep -q "port 99999 is outside \\[0, 65535\\]" "$tmp/e3.txt"'
check "a token file only its owner reads is not warned about" '! grep -q warning "$tmp/e3.txt"'
cat "$tmp/e1.txt" "$tmp/e2.txt" "$tmp/e3.txt"

"$build/server/runtime/viscera-server" --scene "$scene" > "$tmp/server.log" 2>&1 & pids+=($!)
# The session is recorded while the page is tested; the recording is then opened for replay.
mkdir -p "$tmp/recordings"
"$build/tools/viscera-record/viscera-record" --out "$tmp/recordings/session.mcap" --domain "$domain" --quiet > "$tmp/record.log" 2>&1 & recorder=$!; pids+=($recorder)
"$console" --domain "$domain" --token-file "$tmp/token" --listen 127.0.0.1:0 --recordings "$tmp/recordings" --discover > "$tmp/console.log" 2>&1 & bridge=$!; pids+=($bridge)
wait_for "open http" "$tmp/console.log" || exit 1
url="$(grep -o "http://[^ ]*" "$tmp/console.log")?token=$(cat "$tmp/token")"
sleep 1
# --reconnect, as a station's client runs (docs/DEPLOY.md): a stall of the loaded machine (Chromium
# draws in software beside everything) that looks like a lost server is ridden through.
"$build/tools/haptic-client/haptic-client" --domain "$domain" --client-id 1 --instrument 1 --script hold --force 1.2 --duration 150 --reconnect --quiet \
  > "$tmp/haptic.log" 2>&1 & pids+=($!)
shots="${SHOTS:-$tmp}"; mkdir -p "$shots"
HAPTIC_CLIENT="$build/tools/haptic-client/haptic-client" \
  node "$node_dir/console_page.mjs" "$url" "$shots" "$build/tools/viscera-control/viscera-control" --domain "$domain" > "$tmp/page.json" 2> "$tmp/page.err"; rc_page=$?; cat "$tmp/page.err" >&2
check "the page in Chromium (console_page.mjs) $(fails_in "$tmp/page.err")" '[ $rc_page -eq 0 ]'
kill -INT "$recorder"; wait "$recorder"
node "$node_dir/console_replay.mjs" "$url" session.mcap > "$tmp/replay.json" 2> "$tmp/replay.err"; rc_replay=$?; cat "$tmp/replay.err" >&2
check "a recording opened for replay from the console (console_replay.mjs) $(fails_in "$tmp/replay.err")" '[ $rc_replay -eq 0 ]'
node "$node_dir/foxglove_client.mjs" "$url" > "$tmp/foxglove.json" 2> "$tmp/foxglove.err"; rc_foxglove=$?; cat "$tmp/foxglove.err" >&2
check "a Foxglove client on the live session (foxglove_client.mjs) $(fails_in "$tmp/foxglove.err")" '[ $rc_foxglove -eq 0 ]'
# Recordings that cannot be replayed, and a link out of the folder; a link at the path where the
# console once wrote its replays' logs in /tmp (it must not be written through).
: > "$tmp/recordings/empty.mcap"
ln -s /etc/passwd "$tmp/recordings/passwd.mcap"
echo "mine" > "$tmp/victim"; old_log=/tmp/viscera-console-viscera-replay-2.log
[ -e "$old_log" ] || [ -L "$old_log" ] || ln -s "$tmp/victim" "$old_log"
node "$node_dir/console_faults.mjs" "$url" "$bridge" 2 > "$tmp/faults.json" 2> "$tmp/faults.err"; rc_faults=$?; cat "$tmp/faults.err" >&2
check "the console's faults of issue 31 (console_faults.mjs) $(fails_in "$tmp/faults.err")" '[ $rc_faults -eq 0 ]'
check "nothing was written through a link in /tmp" '[ "$(cat "$tmp/victim")" = mine ]'
[ "$(readlink "$old_log")" = "$tmp/victim" ] && rm -f "$old_log"
node "$node_dir/console_robustness.mjs" "$url" "$bridge" > "$tmp/robust.json" 2> "$tmp/robust.err"; rc_robust=$?; cat "$tmp/robust.err" >&2
check "misbehaving browsers (console_robustness.mjs) $(fails_in "$tmp/robust.err")" '[ $rc_robust -eq 0 ]'
check "the bridge still runs" 'kill -0 "$bridge" 2>/dev/null'
check "the access token is in no log line (the address is printed without it)" '! grep -qF "$(cat "$tmp/token")" "$tmp/console.log"'
# Another station's server appears on the domain (partition bay-2, at 200 Hz to spare the CPU): the
# console (--discover) offers it as a station, once; the default station and the replay it opened
# itself are not offered again.
python3 - "$scene" "$tmp/bay2.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["physics_rate_hz"] = 200
s["mesh_rate_hz"] = 10
json.dump(s, open(sys.argv[2], "w"))
PY
"$build/server/runtime/viscera-server" --scene "$tmp/bay2.json" --station bay-2 > "$tmp/bay2.log" 2>&1 & bay2=$!; pids+=($bay2)
wait_for "offered as station bay-2" "$tmp/console.log" 150
python3 -c "import sys, urllib.request; print(urllib.request.urlopen(sys.argv[1].replace('/?', '/stats?')).read().decode())" "$url" > "$tmp/stats.json"
kill -INT $bay2; wait $bay2
grep "offered as station" "$tmp/console.log"
pycheck "$tmp/stats.json" <<'PY'
import json, sys
names = [s["name"] for s in json.load(open(sys.argv[1]))["stations"]]
print(f"stations offered: {names}")
sys.exit(0 if names.count("bay-2") == 1 and len(set(names)) == len(names) and "default" in names and "viscera-replay-1" in names else 1)
PY
check "the server found nothing malformed" 'grep "Hz physics" "$tmp/server.log" | tail -1 | grep -q "malformed 0,"'
# The trainee's client stood by while the console had its instrument: it noticed both ways, and
# the server refused at most the commands sent before it noticed (0.1 s at 1 kHz, with margin).
grep -E "taken over by|handed back" "$tmp/haptic.log"
not_owner=$(grep "Hz physics" "$tmp/server.log" | tail -1 | grep -o "not owner [0-9]*" | grep -o "[0-9]*")
echo "commands refused as not the owner's: $not_owner"
check "the trainee's client stood by while taken over, and drove again after the hand-back" \
  'grep -q "taken over by client" "$tmp/haptic.log" && grep -q "handed back" "$tmp/haptic.log" && [ "${not_owner:-99999}" -le 400 ]'
python3 - "$tmp/page.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
l = d["frame_delay_ms"]
print(f"frame delay, server to page: p50 {l['p50']:.1f} ms, p99 {l['p99']:.1f} ms over {d['frames']} frames")
PY
if [ "$failures" -gt 0 ]; then  # what the failing checks need to be understood
  echo "--- haptic client:"; cat "$tmp/haptic.log"
  echo "--- server (last 15 lines):"; tail -15 "$tmp/server.log"
  echo "--- console (last 15 lines):"; tail -15 "$tmp/console.log"
fi
finish
