#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# clang-tidy with the project's .clang-tidy (its findings are errors) on the C++ sources a change
# touches: those changed since BASE, and for each header changed since BASE that none of them
# includes, one source that does (tests/lint/changed_sources.py, from the build's dependency log).
# BASE: on a branch, its merge base with origin/main; on main itself, the last 3 commits (the work
# just landed); "all" for every source (about 15 minutes on two cores).
# Usage: clang_tidy.sh BUILD_DIR SOURCE_DIR [BASE|all]
set -u
build="$1"; src="$2"; base="${3:-}"
cd "$src" || exit 2
[ -f "$build/compile_commands.json" ] || { echo "clang_tidy: $build/compile_commands.json missing (configure first)"; exit 2; }
if [ -z "$base" ]; then
  head=$(git rev-parse HEAD)
  base=$(git merge-base HEAD origin/main 2> /dev/null || true)
  if [ -z "$base" ] || [ "$base" = "$head" ]; then
    base=HEAD~3
    git rev-parse -q --verify "$base" > /dev/null || base=all
  fi
fi
files=$(python3 "$src/tests/lint/changed_sources.py" "$build" "$src" "$base") || exit 2
[ -z "$files" ] && { echo "clang_tidy: no C++ source changed since $base"; exit 0; }
count=$(echo "$files" | wc -l)
echo "clang_tidy: $count sources (changed since $base, and one includer of each changed header)"
if echo "$files" | xargs -P "$(nproc)" -n 4 clang-tidy -p "$build" --quiet 2>/dev/null | grep -E "(warning|error):"; then
  echo "clang_tidy: findings above (fix them, or justify each with a NOLINT comment that says why)"
  exit 1
fi
echo "clang_tidy: $count sources, no findings"
