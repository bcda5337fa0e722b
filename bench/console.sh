#!/usr/bin/env bash
# The console bridge measured in one run, on the bundled liver with a probe pressing it: the delay
# from a server's surface frame to WebSocket clients (p50, p99), bytes per second per client and
# the bridge's CPU, with 1 and with 4 clients; the DDS leg alone (server -> bridge) beside it; and
# the delay to the real page in headless Chromium. Prints a markdown table and writes
# bench/results/console.json.
# Usage: bench/console.sh [SECONDS]   (default 20 s per measurement)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-20}"
mkdir -p "$root/bench/results"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; pids=()
trap 'kill "${pids[@]}" 2>/dev/null; rm -rf "$tmp"' EXIT
openssl rand -hex 16 > "$tmp/token"
b="$root/build"
"$b/server/runtime/viscera-server" --scene "$root/data/scenes/liver.json" > "$tmp/server.log" 2>&1 & pids+=($!)
"$b/tools/viscera-console/viscera-console" --token-file "$tmp/token" --listen 127.0.0.1:0 > "$tmp/console.log" 2>&1 & bridge=$!; pids+=($bridge)
for _ in $(seq 50); do grep -q "open http" "$tmp/console.log" && break; sleep 0.1; done
url=$(grep -o "http://[^ ]*" "$tmp/console.log")
total=$(( 4 * seconds + 20 ))
"$b/tools/haptic-client/haptic-client" --client-id 1 --instrument 1 --script press --depth 0.03 --duration "$total" --quiet > "$tmp/haptic.log" 2>&1 & pids+=($!)
sleep 2
# The clients are Node scripts in tests/node (Node resolves packages from the script's folder).
node "$root/tests/node/bench_console_load.mjs" "$url" "$bridge" 1 "$seconds" > "$tmp/one.json"
node "$root/tests/node/bench_console_load.mjs" "$url" "$bridge" 4 "$seconds" > "$tmp/four.json"
node "$root/tests/node/bench_console_page_delay.mjs" "$url" "$seconds" > "$tmp/page.json"
python3 - "$tmp/one.json" "$tmp/four.json" "$tmp/page.json" "$root/bench/results/console.json" <<'PY'
import json, os, platform, sys, time
one, four, page = (json.load(open(p)) for p in sys.argv[1:4])
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.machine())
json.dump({"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "machine": f"{cpu}, {os.cpu_count()} CPUs", "seconds": one["seconds"],
           "one": one, "four": four, "page": page}, open(sys.argv[4], "w"), indent=1)
print("| clients | frames | server -> client p50 / p99 [ms] | DDS leg server -> bridge p50 / p99 [ms] | bytes/s per client | bridge CPU [% of a core] |")
print("|---|---|---|---|---|---|")
for r in (one, four):
    print(f"| {r['clients']} WebSocket | {r['frames']} | {r['delay_ms']['p50']:.2f} / {r['delay_ms']['p99']:.2f} | {r['dds_leg_ms']['p50']:.2f} / {r['dds_leg_ms']['p99']:.2f} | {r['bytes_per_s_per_client']/1000:.0f} kB/s | {100*r['bridge_cpu_fraction_of_one_core']:.1f} |")
print(f"| 1 page in headless Chromium | {page['frames']} | {page['delay_ms']['p50']:.2f} / {page['delay_ms']['p99']:.2f} | | | |")
PY
