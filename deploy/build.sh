#!/usr/bin/env bash
# Installs what is missing and builds viscera. Usage: deploy/build.sh [BUILD_DIR] [extra cmake args]
# TARGETS="a b" builds only those targets (default: all).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build}"
shift || true
"$root/deploy/install-deps.sh"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
if [ -n "${TARGETS:-}" ]; then
  # shellcheck disable=SC2086
  cmake --build "$build" -j "$(nproc)" --target $TARGETS
else
  cmake --build "$build" -j "$(nproc)"
fi
