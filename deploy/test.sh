#!/usr/bin/env bash
# Runs every test: installs and builds what is missing, runs the whole suite with ctest, then the
# unit tests of the core once more under AddressSanitizer + UndefinedBehaviorSanitizer.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/deploy/build.sh" "$root/build"
(cd "$root/build" && ctest --output-on-failure -j "$(nproc)")
"$root/deploy/build.sh" "$root/build-sanitize" -DVISCERA_SANITIZE=ON -DVISCERA_BUILD_BENCH=OFF
(cd "$root/build-sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure -j "$(nproc)" -L unit)
