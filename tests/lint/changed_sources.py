#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The C++ sources a change touches: every .cpp changed since BASE, and for each header changed
since BASE that none of those includes, one source that does (its own .cpp where it has one), read
from the build's dependency log (ninja -t deps): clang-tidy reports a header's findings in any
source that includes it, and checking every includer of a widely used header took ten minutes.
A file whose change touches comments only (its SPDX line, a reworded note) is left out: clang-tidy
reads no comment, and the SPDX lines added to every source would have had it check them all.
Prints repository-relative paths, one a line, sorted.

Usage: changed_sources.py BUILD_DIR SOURCE_DIR BASE   (BASE: a commit; "all": every .cpp)"""
import os
import re
import subprocess
import sys


def git(src, *args):
    return subprocess.run(["git", "-C", src, *args], check=True, capture_output=True, text=True).stdout.split("\n")


def code(line):
    """A line without its trailing // comment, when the comment is outside any string literal."""
    m = re.match(r'^(.*?)\s*//.*$', line)
    return (m.group(1) if m and m.group(1).count('"') % 2 == 0 else line).rstrip()


def comments_only(src, base, path):
    """Whether the change to `path` since `base` leaves its code, line by line, as it was."""
    removed, added = [], []
    for line in git(src, "diff", "-U0", "--no-color", base, "--", path):
        if line.startswith("-") and not line.startswith("---"):
            removed.append(code(line[1:]))
        elif line.startswith("+") and not line.startswith("+++"):
            added.append(code(line[1:]))
    return len(removed) == len(added) and removed == added


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    build, src, base = (os.path.realpath(sys.argv[1]), os.path.realpath(sys.argv[2]), sys.argv[3])
    if base == "all":
        sources = {f for f in git(src, "ls-files", "*.cpp") if f}
    else:
        changed = {f for f in git(src, "diff", "--name-only", "--diff-filter=d", base, "--") if f and not comments_only(src, base, f)}
        sources = {f for f in changed if f.endswith(".cpp")}
        headers = {f for f in changed if f.endswith((".hpp", ".h", ".inl"))}
        if headers:
            includers = {h: [] for h in headers}  # header -> sources whose objects include it
            deps = subprocess.run(["ninja", "-C", build, "-t", "deps"], check=True, capture_output=True, text=True).stdout
            source = None
            for line in deps.split("\n"):
                if line and not line.startswith(" "):  # an object: its source is the next line
                    source = None
                    continue
                path = line.strip()
                if not path:
                    continue
                rel = os.path.relpath(os.path.normpath(os.path.join(build, path)), src)
                if source is None:
                    source = rel
                elif rel in includers and source.endswith(".cpp") and not source.startswith(".."):
                    includers[rel].append(source)
            for header, users in includers.items():
                users = sorted(set(users))
                if not users or any(u in sources for u in users):
                    continue
                stem = os.path.splitext(os.path.basename(header))[0]
                own = [u for u in users if os.path.splitext(os.path.basename(u))[0] == stem]
                sources.add((own or users)[0])
    for f in sorted(sources):
        if not f.startswith("tests/fuzz/") and os.path.exists(os.path.join(src, f)):
            print(f)


if __name__ == "__main__":
    main()
