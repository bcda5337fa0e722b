#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""One half of a slow, lossy Ethernet link in user space (the kernel of the project's machines has
no netem qdisc). Each half opens a TAP device in the network namespace it runs in; the two halves
pass whole frames to each other over a Unix socket (which crosses namespaces). Each half delays the
frames its TAP sends by --delay-ms and drops --loss of them (a seeded generator: the same drops for
the same traffic), so each direction of the link gets that delay and that loss once.

Usage: link_relay.py TAP SOCKET (--listen | --connect) [--delay-ms D] [--loss P] [--seed S]
Runs until killed (SIGTERM) or the other half goes away; prints what it relayed and dropped."""
import argparse
import fcntl
import heapq
import os
import random
import select
import signal
import socket
import struct
import sys
import time

TUNSETIFF = 0x400454CA
IFF_TAP, IFF_NO_PI = 0x0002, 0x1000


def open_tap(name):
    fd = os.open("/dev/net/tun", os.O_RDWR)
    fcntl.ioctl(fd, TUNSETIFF, struct.pack("16sH", name.encode(), IFF_TAP | IFF_NO_PI))
    return fd


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("tap")
    a.add_argument("socket")
    side = a.add_mutually_exclusive_group(required=True)
    side.add_argument("--listen", action="store_true")
    side.add_argument("--connect", action="store_true")
    a.add_argument("--delay-ms", type=float, default=0.0)
    a.add_argument("--loss", type=float, default=0.0)
    a.add_argument("--seed", type=int, default=1)
    o = a.parse_args()
    if not 0 <= o.loss < 1 or o.delay_ms < 0:
        sys.exit("link_relay: --loss must lie in [0, 1) and --delay-ms be >= 0")
    tap = open_tap(o.tap)
    if o.listen:
        server = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        server.bind(o.socket)
        server.listen(1)
        print(f"link_relay: {o.tap} waiting on {o.socket}", flush=True)
        peer, _ = server.accept()
    else:
        peer = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        for _ in range(100):
            try:
                peer.connect(o.socket)
                break
            except OSError:
                time.sleep(0.05)
        else:
            sys.exit(f"link_relay: nobody listens on {o.socket}")
    print(f"link_relay: {o.tap} linked, {o.delay_ms} ms delay, {100 * o.loss:.1f}% loss", flush=True)
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    rng = random.Random(o.seed)
    pending = []  # (due, order, frame): frames of our TAP on their way to the other half
    order = sent = dropped = received = 0
    while not stop:
        now = time.monotonic()
        while pending and pending[0][0] <= now:
            peer.send(heapq.heappop(pending)[2])
            sent += 1
        timeout = max(0.0, pending[0][0] - now) if pending else 0.5
        try:
            ready, _, _ = select.select([tap, peer], [], [], timeout)
        except InterruptedError:
            continue
        if tap in ready:
            frame = os.read(tap, 65536)
            if rng.random() < o.loss:
                dropped += 1
            else:
                order += 1
                heapq.heappush(pending, (time.monotonic() + o.delay_ms / 1000, order, frame))
        if peer in ready:
            frame = peer.recv(65536)
            if not frame:
                break
            try:
                os.write(tap, frame)
                received += 1
            except OSError:  # our TAP is not up yet (or going down): the frame is lost, as on a cable
                dropped += 1
    print(f"link_relay: {o.tap}: sent {sent} frames, dropped {dropped}, received {received}", flush=True)


if __name__ == "__main__":
    main()
