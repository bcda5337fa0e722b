#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The soak (bench/soak.sh) for 100 s instead of an hour: a pressing client, a grasping client and a
# console making a request every 10 s against one server. Everything must succeed, the server's
# threads and file descriptors must stay put, and its resident memory must not grow by more than
# 5 MB after a 40 s warm-up (a leak of 100 bytes per 1 kHz command would be 6 MB).
# Usage: soak_test.sh BUILD_DIR SOURCE_DIR
set -u
build="$1"; src="$2"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
BUILD="$build" OUT="$out" SAMPLE_S=5 WARMUP_S=40 "$src/bench/soak.sh" 1.67 > "$out/log.txt" 2>&1
rc=$?
tail -6 "$out/log.txt"
python3 - "$out/soak.json" "$out/soak_samples.csv" "$rc" <<'PY'
import csv, json, sys
r = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
failures = 0
def check(what, ok):
    global failures
    print(("ok   " if ok else "FAIL ") + what)
    failures += not ok
check(f"soak.sh exited 0 (rc {sys.argv[3]}): the server ran throughout and every run and request succeeded", sys.argv[3] == "0")
check(f"clients and console ran ({r['press_runs']} press, {r['grasp_runs']} grasp, {r['console_requests']} requests)",
      r["press_runs"] >= 5 and r["grasp_runs"] >= 8 and r["console_requests"] >= 8)
threads = [int(x["threads"]) for x in rows]
fds = [int(x["fds"]) for x in rows]
# A background build (scene load, material change) adds a thread or two while it runs.
check(f"threads stay put ({min(threads)}-{max(threads)})", max(threads) - min(threads) <= 3 and threads[-1] - threads[1] <= 1)
check(f"file descriptors stay put ({min(fds)}-{max(fds)})", max(fds) - min(fds) <= 2)
warm = [x for x in rows if float(x["t_s"]) >= r["warmup_s"]]
growth_mb = (int(warm[-1]["rss_kb"]) - int(warm[0]["rss_kb"])) / 1024
check(f"resident memory after the warm-up grew {growth_mb:.2f} MB (< 5)", growth_mb < 5)
print(f"[ figure ] soak of {r['minutes'] * 60:.0f} s: RSS {r['series']['rss_kb']['first']:.1f} -> {r['series']['rss_kb']['last']:.1f} MB, "
      f"threads {threads[0]} -> {threads[-1]}, fds {fds[0]} -> {fds[-1]}")
print(f"soak_test: {5 - failures} passed, {failures} failed")
sys.exit(failures > 0)
PY
