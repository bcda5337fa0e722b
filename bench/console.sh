#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The console bridge measured in one run, on the bundled liver with a probe pressing it: the delay
# from a server's surface frame to WebSocket clients (p50, p99), bytes per second per client and
# the bridge's CPU, with 1 and with 4 clients; the DDS leg alone (server -> bridge) beside it; and
# the delay to the real page in headless Chromium. Two bridges watch the same server side by side,
# one over plain HTTP and WebSocket, one over HTTPS and WSS (the test PKI's certificate, verified
# by the clients: Node through NODE_EXTRA_CA_CERTS, Chromium through its certificate store),
# measured in turn. Prints a markdown table and writes bench/results/console.json.
# Usage: bench/console.sh [SECONDS]   (default 20 s per measurement)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-20}"
mkdir -p "$root/bench/results"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true; rm -rf "$tmp"' EXIT
openssl rand -hex 16 > "$tmp/token"; chmod 600 "$tmp/token"
"$root/deploy/dds/make-test-pki.sh" "$tmp/pki" bench > /dev/null
mkdir -p "$tmp/home/.pki/nssdb"
certutil -N -d "sql:$tmp/home/.pki/nssdb" --empty-password
certutil -A -d "sql:$tmp/home/.pki/nssdb" -n "viscera test CA" -t "C,," -i "$tmp/pki/ca.pem"
b="$root/build"
"$b/server/runtime/viscera-server" --scene "$root/data/scenes/liver.json" > "$tmp/server.log" 2>&1 & pids+=($!)
"$b/tools/viscera-console/viscera-console" --token-file "$tmp/token" --listen 127.0.0.1:0 > "$tmp/console.log" 2>&1 & bridge=$!; pids+=($bridge)
"$b/tools/viscera-console/viscera-console" --token-file "$tmp/token" --listen 127.0.0.1:0 --client-id 951 \
  --tls-cert "$tmp/pki/console-web.pem" --tls-key "$tmp/pki/console-web.key" > "$tmp/console-tls.log" 2>&1 & bridge_tls=$!; pids+=($bridge_tls)
for _ in $(seq 50); do grep -q "open http" "$tmp/console.log" && grep -q "open https" "$tmp/console-tls.log" && break; sleep 0.1; done
url="$(grep -o "http://[^ ]*" "$tmp/console.log")?token=$(cat "$tmp/token")"; url_tls="$(grep -o "https://[^ ]*" "$tmp/console-tls.log")?token=$(cat "$tmp/token")"
total=$(( 8 * seconds + 30 ))
"$b/tools/haptic-client/haptic-client" --client-id 1 --instrument 1 --script press --depth 0.03 --duration "$total" --quiet > "$tmp/haptic.log" 2>&1 & pids+=($!)
sleep 2
# The clients are Node scripts in tests/node (Node resolves packages from the script's folder).
export NODE_EXTRA_CA_CERTS="$tmp/pki/ca.pem"
for n in 1 4; do
  node "$root/tests/node/bench_console_load.mjs" "$url" "$bridge" "$n" "$seconds" > "$tmp/plain-$n.json"
  node "$root/tests/node/bench_console_load.mjs" "$url_tls" "$bridge_tls" "$n" "$seconds" > "$tmp/tls-$n.json"
done
HOME="$tmp/home" node "$root/tests/node/bench_console_page_delay.mjs" "$url" "$seconds" > "$tmp/page.json"
HOME="$tmp/home" node "$root/tests/node/bench_console_page_delay.mjs" "$url_tls" "$seconds" > "$tmp/page-tls.json"
python3 - "$tmp" "$root/bench/results/console.json" <<'PY'
import json, os, platform, sys, time
d = sys.argv[1]
r = {f"{kind}-{n}": json.load(open(f"{d}/{kind}-{n}.json")) for kind in ("plain", "tls") for n in (1, 4)}
page = {"plain": json.load(open(f"{d}/page.json")), "tls": json.load(open(f"{d}/page-tls.json"))}
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.machine())
json.dump({"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "machine": f"{cpu}, {os.cpu_count()} CPUs", "seconds": r["plain-1"]["seconds"],
           "one": r["plain-1"], "four": r["plain-4"], "page": page["plain"], "tls_one": r["tls-1"], "tls_four": r["tls-4"], "tls_page": page["tls"]},
          open(sys.argv[2], "w"), indent=1)
print("| clients | transport | frames | server -> client p50 / p99 [ms] | DDS leg server -> bridge p50 / p99 [ms] | bytes/s per client | bridge CPU [% of a core] |")
print("|---|---|---|---|---|---|---|")
for n in (1, 4):
    for kind, name in (("plain", "ws"), ("tls", "wss")):
        x = r[f"{kind}-{n}"]
        print(f"| {n} WebSocket | {name} | {x['frames']} | {x['delay_ms']['p50']:.2f} / {x['delay_ms']['p99']:.2f} | {x['dds_leg_ms']['p50']:.2f} / {x['dds_leg_ms']['p99']:.2f} | {x['bytes_per_s_per_client']/1000:.0f} kB/s | {100*x['bridge_cpu_fraction_of_one_core']:.1f} |")
for kind, name in (("plain", "http, ws"), ("tls", "https, wss")):
    print(f"| 1 page in headless Chromium | {name} | {page[kind]['frames']} | {page[kind]['delay_ms']['p50']:.2f} / {page[kind]['delay_ms']['p99']:.2f} | | | |")
PY
