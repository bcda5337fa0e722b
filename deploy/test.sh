#!/usr/bin/env bash
# Runs every test: installs and builds what is missing, then
#  1. the whole suite in Release with ctest (unit, lab, physics, tools, integration over a real DDS
#     domain, the fuzz targets, the soak, and lint: clang-format on every file, clang-tidy on the
#     sources changed by the last 3 commits);
#  2. under AddressSanitizer + UndefinedBehaviorSanitizer (built at -O1), every test that can run under them: the
#     unit, lab and command-line tests. Left out, with the reason: the three "physics" tests (12k
#     liver presses, ten minutes of sanitized tissue loop; the same code runs sanitized in the unit
#     tests on smaller meshes) and the multi-process tests, which assert real-time rates (1 kHz) that
#     a sanitized build cannot hold; their server code runs sanitized in one process in
#     ServerThreads (endpoints in memory);
#  3. under ThreadSanitizer, the server's threading tests: the whole server in one process (the
#     command thread against the physics thread, the snapshot hand-over, a material built in the
#     background), the parallel forces, session control and the instrument table.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/deploy/build.sh" "$root/build"
(cd "$root/build" && ctest --output-on-failure -j "$(nproc)")
"$root/deploy/build.sh" "$root/build-sanitize" -DVISCERA_SANITIZE=ON -DVISCERA_BUILD_BENCH=OFF
(cd "$root/build-sanitize" && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --output-on-failure -j "$(nproc)" -L 'unit|lab|tools')
threads="server_threads_test parallel_forces_test session_control_test instrument_table_test"
TARGETS="$threads" "$root/deploy/build.sh" "$root/build-tsan" -DVISCERA_SANITIZE=thread -DVISCERA_BUILD_BENCH=OFF
for t in $threads; do
  echo "ThreadSanitizer: $t"
  TSAN_OPTIONS="halt_on_error=1 suppressions=$root/tests/runtime/tsan.supp" "$root/build-tsan/tests/runtime/$t" --gtest_brief=1
done
