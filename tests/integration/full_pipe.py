#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Runs a command whose standard output is a pipe filled to its last byte, as a pipe nobody reads
(or a terminal stopped with Ctrl-S) is: every write to it blocks. After --read-after seconds the
pipe is read (with --interrupt the command then gets SIGINT); prints when that was, the command's
exit status, and the lines it wrote, the last one in full.

Usage: full_pipe.py --read-after S [--interrupt] -- COMMAND [ARGUMENT...]"""
import argparse
import os
import signal
import subprocess
import sys
import threading
import time

parser = argparse.ArgumentParser(usage=__doc__)
parser.add_argument("--read-after", type=float, required=True)
parser.add_argument("--interrupt", action="store_true")
parser.add_argument("command", nargs=argparse.REMAINDER)
a = parser.parse_args()
command = a.command[1:] if a.command[:1] == ["--"] else a.command
if not command:
    sys.exit("full_pipe.py: no command")
r, w = os.pipe()
os.set_blocking(w, False)
for size in (4096, 1):
    try:
        while True:
            os.write(w, b"x" * size)
    except BlockingIOError:
        pass
os.set_blocking(w, True)
p = subprocess.Popen(command, stdout=w)
os.close(w)
time.sleep(a.read_after)
print(f"read at {time.time():.3f}", flush=True)
got = []


def drain():
    while b := os.read(r, 65536):
        got.append(b)


threading.Thread(target=drain, daemon=True).start()
if a.interrupt:
    p.send_signal(signal.SIGINT)
print(f"exit status {p.wait(timeout=30)}")
time.sleep(0.3)
lines = b"".join(got).decode(errors="replace").replace("x", "").splitlines()
print(f"{len(lines)} lines once read; the last: {lines[-1] if lines else ''}")
