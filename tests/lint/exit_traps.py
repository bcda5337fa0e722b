#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Every shell script's EXIT trap runs to its end. Under `set -e` a command that fails inside the
trap stops it there and the script exits 1: a `kill` of a process that has already exited (the
usual case at the end of a run) then skipped the `rm -rf` of the temporary folder, so each
bench/station.sh run left 3 GB in /tmp and reported failure after a good run. A `kill` or `wait`
in a trap must therefore end in `|| true`. Prints each trap that does not.
Usage: exit_traps.py SOURCE_DIR"""
import re
import subprocess
import sys

root = sys.argv[1]
files = subprocess.run(["git", "-C", root, "ls-files", "*.sh"], capture_output=True, text=True, check=True).stdout.split()
bad = []
for path in files:
    text = open(f"{root}/{path}", encoding="utf-8").read()
    for m in re.finditer(r"trap '([^']*)' EXIT", text):
        line = text.count("\n", 0, m.start()) + 1
        for command in m.group(1).split(";"):
            command = command.strip()
            if re.match(r"(kill|wait)\b", command) and not command.endswith("|| true"):
                bad.append(f"{path}:{line}: '{command}' in an EXIT trap can fail and stop the trap (end it in '|| true')")
if bad:
    print("\n".join(bad))
    sys.exit(1)
print(f"exit_traps: the EXIT traps of {len(files)} shell scripts run to their end")
