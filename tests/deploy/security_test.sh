#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# DDS Security, with real processes on one DDS domain (deploy/dds/secure.xml and a test PKI from
# deploy/dds/make-test-pki.sh, stations bay-1 and bay-2):
#  - the authorized server, haptic client, trainer, console identity and recorder work as before:
#    the press produces forces, the recorder records them, the trainer pauses and resumes;
#  - a participant without security, and one whose certificate a rogue CA signed (with the very
#    subject of the station's haptic identity), find no server and move nothing;
#  - an identity whose permissions do not grant it cannot act: the recorder cannot publish, the
#    trainer cannot command an instrument, bay-2's haptic station cannot join bay-1;
#  - an authorized participant cannot act under another client's id (the server binds ids to the
#    certificate that first used them), also once that client has gone silent; the client's own
#    certificate, restarted, takes its id back;
#  - the round trip with authentication and encryption, against the same press without them.
# Usage: security_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
server=; holder=
recorder=
trap 'kill $server $holder $recorder 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
hc="$build/tools/haptic-client/haptic-client"; ctl="$build/tools/viscera-control/viscera-control"
rec="$build/tools/viscera-record/viscera-record"; hostile="$build/tests/integration/hostile_publisher"

plugins=$(dirname "$(dpkg -L libddsc0debian 2>/dev/null | grep 'libdds_security_auth.so$' | head -1)" 2>/dev/null)
if ! command -v openssl >/dev/null || [ ! -f "$plugins/libdds_security_auth.so" ]; then
  echo "security_test: SKIPPED every case: openssl or Debian's DDS Security plugins (libddsc0debian) are missing"
  exit 0
fi
export VISCERA_DDS_PLUGINS="$plugins" VISCERA_PKI="$tmp/pki"
"$src/deploy/dds/make-test-pki.sh" "$tmp/pki" bay-1 bay-2 > "$tmp/pki.log" 2>&1 || { cat "$tmp/pki.log"; exit 1; }
plain="file://$src/deploy/dds/loopback.xml"
secure="$plain,file://$src/deploy/dds/secure.xml"
as() {  # IDENTITY COMMAND...: runs the command as that identity, with DDS Security (env execs it:
  # started in the background, $! is the program itself)
  env CYCLONEDDS_URI="$secure" VISCERA_IDENTITY="$1" "${@:2}"
}

# The same press without security first, for the cost of encryption.
CYCLONEDDS_URI="$plain" "$build/server/runtime/viscera-server" --scene "$scene" --station bay-1 > "$tmp/plain-server.log" 2>&1 & server=$!
wait_for "DDS domain" "$tmp/plain-server.log" 100
CYCLONEDDS_URI="$plain" "$hc" --domain "$domain" --station bay-1 --client-id 11 --duration 4 --quiet --report "$tmp/plain.json" > "$tmp/plain.log" 2>&1
rc_plain=$?
kill -INT $server; wait $server; server=

env CYCLONEDDS_URI="$secure" VISCERA_IDENTITY=server-bay-1 "$build/server/runtime/viscera-server" --scene "$scene" --station bay-1 > "$tmp/server.log" 2>&1 &
server=$!
wait_for "station bay-1" "$tmp/server.log" 100

# Authorized: the recorder records the station while its haptic station presses.
env CYCLONEDDS_URI="$secure" VISCERA_IDENTITY=recorder "$rec" --domain "$domain" --station bay-1 --out "$tmp/secure.mcap" --duration 7 > "$tmp/rec.log" 2>&1 &
recorder=$!
sleep 1
as haptic-bay-1 "$hc" --domain "$domain" --station bay-1 --client-id 11 --duration 4 --quiet --report "$tmp/secure.json" > "$tmp/secure.log" 2>&1
rc_secure=$?
cat "$tmp/plain.log" "$tmp/secure.log"
check "the press ran without security (rc $rc_plain)" "[ $rc_plain -eq 0 ]"
check "the haptic station pressed its station's organ with DDS Security (rc $rc_secure)" "[ $rc_secure -eq 0 ] && grep -q 'contact at' '$tmp/secure.log'"

# The trainer's identity may pause and resume (session requests) but not command an instrument.
as trainer-bay-1 "$ctl" pause --domain "$domain" --station bay-1 --client-id 800 > "$tmp/trainer.log" 2>&1; rc_pause=$?
as trainer-bay-1 "$ctl" resume --domain "$domain" --station bay-1 --client-id 800 >> "$tmp/trainer.log" 2>&1; rc_resume=$?
as trainer-bay-1 "$hc" --domain "$domain" --station bay-1 --client-id 801 --duration 1 --quiet > "$tmp/trainer-hc.log" 2>&1; rc_trainer_hc=$?
check "the trainer's identity paused and resumed the station (rc $rc_pause, $rc_resume)" \
  "[ $rc_pause -eq 0 ] && [ $rc_resume -eq 0 ] && grep -q 'client 800 paused' '$tmp/server.log'"
check "the trainer's identity cannot command an instrument (rc $rc_trainer_hc)" \
  "[ $rc_trainer_hc -ne 0 ] && grep -q 'create writer of viscera_instrument_command in station .bay-1.: Not Allowed By Security' '$tmp/trainer-hc.log'"

# The recorder's identity cannot publish anything; bay-2's haptic station cannot join bay-1.
as recorder "$ctl" pause --domain "$domain" --station bay-1 > "$tmp/rec-pause.log" 2>&1; rc_rec_pause=$?
as haptic-bay-2 "$hc" --domain "$domain" --station bay-1 --client-id 12 --duration 1 --quiet > "$tmp/bay2.log" 2>&1; rc_bay2=$?
as recorder "$hostile" "$domain" 1 --station bay-1 > "$tmp/rec-hostile.log" 2>&1; rc_rec_hostile=$?
cat "$tmp/rec-pause.log" "$tmp/bay2.log" "$tmp/rec-hostile.log"
check "the recorder's identity cannot send a session request (rc $rc_rec_pause)" \
  "[ $rc_rec_pause -ne 0 ] && grep -q 'viscera_session_request in station .bay-1.: Not Allowed By Security' '$tmp/rec-pause.log'"
check "the recorder's identity cannot publish commands (rc $rc_rec_hostile)" "[ $rc_rec_hostile -eq 3 ] && grep -q 'Not Allowed By Security' '$tmp/rec-hostile.log'"
check "bay-2's haptic station cannot act in bay-1 (rc $rc_bay2)" "[ $rc_bay2 -ne 0 ] && grep -q 'Not Allowed By Security' '$tmp/bay2.log'"

# Without a valid certificate: a participant without security, and one with a certificate from a
# rogue CA bearing the haptic station's very subject, find no server; their hostile traffic
# (garbage, commands, releases) never reaches it.
mkdir -p "$tmp/rogue"
"$src/deploy/dds/make-test-pki.sh" "$tmp/rogue" bay-1 > /dev/null 2>&1
CYCLONEDDS_URI="$plain" timeout 20 "$ctl" show --domain "$domain" --station bay-1 > "$tmp/plain-ctl.log" 2>&1; rc_plain_ctl=$?
VISCERA_PKI="$tmp/rogue" as haptic-bay-1 timeout 20 "$ctl" show --domain "$domain" --station bay-1 > "$tmp/rogue-ctl.log" 2>&1; rc_rogue_ctl=$?
CYCLONEDDS_URI="$plain" "$hostile" "$domain" 2 --station bay-1 > /dev/null 2>&1
VISCERA_PKI="$tmp/rogue" as haptic-bay-1 "$hostile" "$domain" 2 --station bay-1 > /dev/null 2>&1
cat "$tmp/plain-ctl.log" "$tmp/rogue-ctl.log"
check "a participant without security finds no server (rc $rc_plain_ctl)" "[ $rc_plain_ctl -eq 3 ] && grep -q 'no viscera-server' '$tmp/plain-ctl.log'"
check "a participant with a rogue CA's certificate finds no server (rc $rc_rogue_ctl)" "[ $rc_rogue_ctl -eq 3 ] && grep -q 'no viscera-server' '$tmp/rogue-ctl.log'"

# An authorized participant under another client's id: the console's identity may publish
# commands and releases in bay-1, but not as client 21, whose instrument a haptic station holds.
env CYCLONEDDS_URI="$secure" VISCERA_IDENTITY=haptic-bay-1 "$hc" --domain "$domain" --station bay-1 --client-id 21 --instrument 2 --duration 6 --depth 0.01 --quiet > "$tmp/holder.log" 2>&1 &
holder=$!
wait_for "claimed" "$tmp/holder.log" 100
as console "$hostile" "$domain" release 2 21 --station bay-1 > "$tmp/impostor.log" 2>&1; rc_impostor=$?
wait $holder; rc_holder=$?; holder=
cat "$tmp/impostor.log" "$tmp/holder.log"
check "the console's identity may publish in bay-1 (rc $rc_impostor)" "[ $rc_impostor -eq 0 ]"
check "its release under another client's id was refused: the holder kept its instrument (rc $rc_holder)" \
  "[ $rc_holder -eq 0 ] && ! grep -q 'no longer this client' '$tmp/holder.log'"
# Client 21 has gone silent (its process ended): its id stays with its certificate. The console's
# identity still cannot claim as client 21; the haptic station's certificate, restarted, can.
sleep 1
as console "$hc" --domain "$domain" --station bay-1 --client-id 21 --instrument 2 --duration 1 --quiet > "$tmp/console-as-21.log" 2>&1; rc_console21=$?
as haptic-bay-1 "$hc" --domain "$domain" --station bay-1 --client-id 21 --instrument 2 --duration 1 --depth 0.01 --quiet > "$tmp/again-21.log" 2>&1; rc_again21=$?
cat "$tmp/console-as-21.log" "$tmp/again-21.log"
check "another certificate cannot take a silent client's id (rc $rc_console21)" "[ $rc_console21 -eq 3 ] && grep -q 'instrument 2 not claimed' '$tmp/console-as-21.log'"
check "the id's own certificate, restarted, takes it back (rc $rc_again21)" "[ $rc_again21 -eq 0 ] && grep -q 'instrument 2 claimed' '$tmp/again-21.log'"
check "the server binds client ids to certificates here" "grep -q 'client ids bound to the certificate' '$tmp/server.log'"

wait $recorder; rc_rec=$?
kill -INT $server; wait $server; rc_server=$?; server=
tail -2 "$tmp/server.log"
check "the recorder recorded the station (rc $rc_rec)" "[ $rc_rec -eq 0 ] && grep -q 'force_feedback' '$tmp/rec.log'"
check "the server stopped cleanly (rc $rc_server)" "[ $rc_server -eq 0 ]"
# Nothing of the unauthenticated traffic arrived: the server's only refusals are the impostors'
# (the release, and the console's claims and commands as client 21).
check "no unauthenticated message reached the server, the impostors' messages were counted" \
  "grep 'stopped after' '$tmp/server.log' | grep -qE \"\\(malformed 0, not owner 0, unknown instrument 0, another participant's client id ([2-9]|[1-9][0-9]+)\\)\""
pycheck "$tmp/plain.json" "$tmp/secure.json" <<'PY'
import json, sys
p, s = (json.load(open(f)) for f in sys.argv[1:3])
def rt(r, key): return r["round_trip_us"][key]
print(f"[ figure ] round trip without security p50 {rt(p, 'p50'):.0f} us p99 {rt(p, 'p99'):.0f} us; "
      f"authenticated and encrypted p50 {rt(s, 'p50'):.0f} us p99 {rt(s, 'p99'):.0f} us "
      f"(ratio p50 {rt(s, 'p50') / rt(p, 'p50'):.2f}, p99 {rt(s, 'p99') / rt(p, 'p99'):.2f})")
sys.exit(0 if rt(s, "p50") > 0 and rt(p, "p50") > 0 else 1)
PY
finish
