#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# A 1 kHz haptic loop written in Python (examples/python/haptic_client.py) against the C++
# haptic-client, in one run on one server (the 1.5k liver, loopback): each presses for SECONDS
# (default 60), one after the other, REPEAT times interleaved. Reports the command-to-force round
# trip (p50, p99, max) and the periods over 2 ms of each, and the Python loop's p99 minus the C++
# client's. Writes bench/results/python_loop.json.
# Usage: [REPEAT=1] bench/python_loop.sh [SECONDS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
mkdir -p "$root/bench/results"
"$root/deploy/build.sh" "$root/build" >/dev/null
export CYCLONEDDS_URI="file://$root/deploy/dds/loopback.xml"
tmp="$(mktemp -d)"; trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
domain=$(( (RANDOM % 200) + 1 ))
sed "s/\"domain_id\": 0/\"domain_id\": $domain/; s#\"../meshes/#\"$root/data/meshes/#; s#\"../materials/#\"$root/data/materials/#" \
  "$root/data/scenes/liver.json" > "$tmp/scene.json"
"$root/build/server/runtime/viscera-server" --scene "$tmp/scene.json" > "$tmp/server.log" 2>&1 &
for _ in $(seq 300); do grep -q "Hz physics" "$tmp/server.log" && break; sleep 0.1; done
python="$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' "$root/build/CMakeCache.txt")"
for rep in $(seq "${REPEAT:-1}"); do
  echo "python_loop.sh: run $rep: the C++ haptic-client, $seconds s at 1 kHz ..."
  "$root/build/tools/haptic-client/haptic-client" --domain "$domain" --client-id 11 --instrument 1 --duration "$seconds" --depth 0.01 \
    --report "$tmp/cpp-$rep.json" --quiet > /dev/null 2>&1
  echo "python_loop.sh: run $rep: the Python client, $seconds s at 1 kHz ..."
  PYTHONPATH="$root/build/python" "$python" "$root/examples/python/haptic_client.py" --domain "$domain" --client-id 12 --instrument 1 \
    --duration "$seconds" --depth 0.01 --report "$tmp/python-$rep.json" > /dev/null
done
"$python" - "$tmp" "${REPEAT:-1}" "$seconds" "$root/bench/results/python_loop.json" <<'PY'
import json, platform, re, sys
tmp, repeat, seconds, out = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
def late(starts, limit_s=0.002):
    gaps = [b - a for a, b in zip(starts, starts[1:])]
    return sum(g > limit_s for g in gaps), len(gaps)
rows = []
print("| run | client | round trip p50 [us] | p99 [us] | max [us] | periods | over 2 ms |")
print("|---|---|---|---|---|---|---|")
for r in range(1, repeat + 1):
    cpp = json.load(open(f"{tmp}/cpp-{r}.json"))
    py = json.load(open(f"{tmp}/python-{r}.json"))
    cpp_late, cpp_periods = late([s["t_s"] for s in cpp["samples"]])
    py_late, py_periods = late(py["period_starts_s"])
    for name, rt, n, l in (("C++ haptic-client", cpp["round_trip_us"], cpp_periods, cpp_late), ("Python", py["round_trip_us"], py_periods, py_late)):
        print(f"| {r} | {name} | {rt['p50']:.0f} | {rt['p99']:.0f} | {rt['max']:.0f} | {n} | {l} ({100.0 * l / max(n, 1):.3f}%) |")
    rows.append({"cpp": {"round_trip_us": cpp["round_trip_us"], "periods": cpp_periods, "over_2ms": cpp_late},
                 "python": {"round_trip_us": py["round_trip_us"], "periods": py_periods, "over_2ms": py_late},
                 "p99_difference_us": py["round_trip_us"]["p99"] - cpp["round_trip_us"]["p99"]})
    print(f"run {r}: Python p99 - C++ p99 = {rows[-1]['p99_difference_us']:.0f} us (target at most 250 us); Python periods over 2 ms "
          f"{100.0 * py_late / max(py_periods, 1):.3f}% (target at most 0.1%)")
cpu = re.search(r"model name\s*:\s*(.*)", open("/proc/cpuinfo").read())
json.dump({"seconds": seconds, "runs": rows, "machine": f"{cpu.group(1) if cpu else platform.processor()}, {platform.node()}"}, open(out, "w"), indent=1)
print(f"wrote {out}")
PY
