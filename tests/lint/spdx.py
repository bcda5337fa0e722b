#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Every source file of the project's own (C++, scripts, Python, CMake, schemas, the page,
configurations; not the data in data/, which carries its own licenses) names its license with an
SPDX line in its first three lines: `SPDX-License-Identifier: Apache-2.0` (LICENSE). In C and C++
files it ends the first line (`#pragma once  // SPDX-...`): a line of its own would move every
line below it, and with them the preprocessed text every compiler cache keys on, so one commit
would rebuild every tree cold. Prints each file that does not. Usage: spdx.py SOURCE_DIR"""
import re
import subprocess
import sys

root = sys.argv[1]
own = re.compile(r"(\.(cpp|hpp|h|c|sh|py|pyi|fbs|idl|mjs|js|css|html|cmake|yaml|service|xml)|CMakeLists\.txt|Dockerfile|^\.ci/run)$")
files = [f for f in subprocess.run(["git", "-C", root, "ls-files"], capture_output=True, text=True, check=True).stdout.split()
         if own.search(f) and not f.startswith("data/")]
bad = [f for f in files if "SPDX-License-Identifier: Apache-2.0" not in "".join(open(f"{root}/{f}", encoding="utf-8").readlines()[:3])]
if bad:
    print("\n".join(f"{f}: no 'SPDX-License-Identifier: Apache-2.0' in its first three lines" for f in bad))
    sys.exit(1)
print(f"spdx: {len(files)} source files name their license")
