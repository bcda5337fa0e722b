#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every C++ file is laid out as .clang-format says (clang-format 14). Prints the files that are not.
# Usage: format_check.sh SOURCE_DIR
set -u
cd "$1" || exit 2
bad=()
while IFS= read -r f; do
  clang-format --dry-run --Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done < <(git ls-files '*.cpp' '*.hpp')
if [ ${#bad[@]} -gt 0 ]; then
  printf 'not formatted (run: clang-format -i FILE): %s\n' "${bad[@]}"
  exit 1
fi
echo "format_check: every C++ file follows .clang-format"
