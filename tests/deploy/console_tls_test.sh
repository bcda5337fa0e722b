#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The console serves HTTPS and WSS itself (issue 33): a server (the 1.5k liver) and a console with
# the test PKI's web certificate (deploy/dds/make-test-pki.sh), judged by clients that verify the
# certificate against the test CA (tests/node/console_tls.mjs: Node's OpenSSL, the ws client, and
# Debian's Chromium with the CA in its certificate store). Also what the console refuses: plain
# HTTP beyond loopback, a key that is not the certificate's, a certificate file that is not one,
# an expired certificate, and a plain HTTP request on its TLS port (told to use https).
# Usage: console_tls_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$(cd "$2" && pwd)"
. "$src/tests/integration/common.sh"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; show_output; rm -rf "$tmp"' EXIT
console="$build/tools/viscera-console/viscera-console"
command -v certutil >/dev/null || { echo "FAIL certutil is not installed (deploy/install-deps.sh installs libnss3-tools)"; exit 1; }
[ -d "$src/tests/node/node_modules/playwright-core" ] || { echo "FAIL playwright-core is not installed (deploy/install-deps.sh runs npm ci in tests/node)"; exit 1; }
"$src/deploy/dds/make-test-pki.sh" "$tmp/pki" bay-1 > /dev/null || { echo "FAIL make-test-pki.sh"; exit 1; }
VISCERA_CONSOLE_HOSTS="10.1.2.3" "$src/deploy/dds/make-test-pki.sh" "$tmp/other" bay-1 > /dev/null || { echo "FAIL make-test-pki.sh (other)"; exit 1; }
openssl rand -hex 16 > "$tmp/token"; chmod 600 "$tmp/token"
pki="$tmp/pki"

# Refusals.
"$console" --token-file "$tmp/token" --listen 0.0.0.0:0 > "$tmp/e1.txt" 2>&1; rc=$?
check "plain HTTP beyond loopback is refused (rc $rc)" '[ $rc -eq 2 ] && grep -q "is not a loopback address: a console other hosts reach serves HTTPS only" "$tmp/e1.txt"'
"$console" --token-file "$tmp/token" --tls-cert "$pki/console-web.pem" --tls-key "$tmp/other/console-web.key" > "$tmp/e2.txt" 2>&1; rc=$?
check "a key that is not the certificate's (rc $rc)" '[ $rc -eq 2 ] && grep -q "other/console-web.key: private key: .*key values mismatch" "$tmp/e2.txt"'
"$console" --token-file "$tmp/token" --tls-cert "$tmp/token" --tls-key "$pki/console-web.key" > "$tmp/e3.txt" 2>&1; rc=$?
check "a certificate file that holds no certificate (rc $rc)" '[ $rc -eq 2 ] && grep -q "token: certificate: not a PEM certificate chain" "$tmp/e3.txt"'
# A certificate from the test CA that was valid in 2020 only (openssl ca dates it back).
mkdir "$tmp/old"; : > "$tmp/old/index.txt"
printf '[ca]\ndefault_ca=d\n[d]\ndatabase=%s/old/index.txt\nserial=%s/old/serial\nnew_certs_dir=%s/old\ndefault_md=sha256\npolicy=p\n[p]\ncommonName=supplied\n' "$tmp" "$tmp" "$tmp" > "$tmp/old/ca.cnf"
openssl req -new -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -keyout "$tmp/old.key" -subj /CN=old -out "$tmp/old/old.csr" 2> /dev/null
openssl ca -batch -config "$tmp/old/ca.cnf" -create_serial -cert "$pki/ca.pem" -keyfile "$pki/ca.key" -in "$tmp/old/old.csr" \
  -startdate 20200101000000Z -enddate 20210101000000Z -out "$tmp/old.pem" 2> "$tmp/old/err" || cat "$tmp/old/err"
"$console" --token-file "$tmp/token" --tls-cert "$tmp/old.pem" --tls-key "$tmp/old.key" > "$tmp/e4.txt" 2>&1; rc=$?
check "an expired certificate (rc $rc)" '[ $rc -eq 2 ] && grep -q "old.pem: certificate: has expired" "$tmp/e4.txt"'
"$console" --token-file "$tmp/token" --tls-cert "$pki/console-web.pem" > "$tmp/e5.txt" 2>&1; rc=$?
check "--tls-cert without --tls-key (rc $rc)" '[ $rc -eq 2 ] && grep -q "go together" "$tmp/e5.txt"'
cat "$tmp"/e[1-5].txt

# Chromium's certificate stores: one that trusts the test CA, one that does not.
mkdir -p "$tmp/home-ca/.pki/nssdb" "$tmp/home-bare/.pki/nssdb"
certutil -N -d "sql:$tmp/home-ca/.pki/nssdb" --empty-password && certutil -N -d "sql:$tmp/home-bare/.pki/nssdb" --empty-password
certutil -A -d "sql:$tmp/home-ca/.pki/nssdb" -n "viscera test CA" -t "C,," -i "$pki/ca.pem"
check "the test CA is in the first store" 'certutil -L -d "sql:$tmp/home-ca/.pki/nssdb" | grep -q "viscera test CA"'

python3 - "$scene" "$tmp/slow.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["physics_rate_hz"] = 250  # the browser test needs frames, not 1 kHz; it spares the CPU for Chromium
json.dump(s, open(sys.argv[2], "w"))
PY
"$build/server/runtime/viscera-server" --scene "$tmp/slow.json" --station bay-1 > "$tmp/server.log" 2>&1 & pids+=($!)
"$console" --domain "$domain" --stations bay-1 --listen 127.0.0.1:0 --token-file "$tmp/token" \
  --tls-cert "$pki/console-web.pem" --tls-key "$pki/console-web.key" > "$tmp/console.log" 2>&1 & pids+=($!)
wait_for "station(s); open https" "$tmp/console.log" 100 || exit 1
url="$(grep -o 'https://[^ ]*' "$tmp/console.log" | head -1)?token=$(cat "$tmp/token")"
wait_for "station bay-1" "$tmp/server.log" 150 || exit 1
plain=$(curl -s --max-time 5 "${url/https/http}")
check "a plain HTTP request on the TLS port is told to use https" '[[ "$plain" == *"speaks HTTPS only"* ]]'
curl -sS --max-time 5 --cacert "$pki/ca.pem" -o /dev/null -w "%{http_code}" "$url" > "$tmp/curl.txt" 2> "$tmp/curl.err"
check "curl --cacert verifies the console ($(cat "$tmp/curl.txt"))" '[ "$(cat "$tmp/curl.txt")" = 200 ]'
curl -sS --max-time 5 -o /dev/null "$url" 2> "$tmp/curl-bare.err"; rc=$?
check "curl without the test CA refuses (rc $rc)" '[ $rc -eq 60 ]'
node "$src/tests/node/console_tls.mjs" "$url" "$pki/ca.pem" "$tmp/other/ca.pem" "$tmp/home-ca" "$tmp/home-bare" > "$tmp/tls.json"; rc=$?
check "clients that verify the certificate (console_tls.mjs)" '[ $rc -eq 0 ]'
curl -s --cacert "$pki/ca.pem" "${url/\/\?/\/stats?}" > "$tmp/stats.json"
pycheck "$tmp/stats.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(f"console: tls {s['tls']}, {s['tls_handshakes_failed']} TLS handshakes refused, {s['plain_http_refused']} plain HTTP requests refused")
sys.exit(0 if s["tls"] and s["tls_handshakes_failed"] >= 3 and s["plain_http_refused"] >= 1 else 1)
PY
check "the console still runs" 'kill -0 "${pids[1]}"'
finish
