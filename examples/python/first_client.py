# SPDX-License-Identifier: Apache-2.0
"""A first haptic client: claims probe 1, presses it 2 cm into the organ from above at 1 kHz, prints the force."""
import sys
import time

import viscera

client = viscera.session.Client(int(sys.argv[1]) if len(sys.argv) > 1 else 0, 43)  # DDS domain, this client's id
scene = client.wait_for_scene(10.0)
if scene is None or not client.claim(1, 5.0):
    sys.exit("no viscera-server on this domain, or its probe 1 is taken")
x, y = ((a + b) / 2 for a, b in zip(scene.bounds_min_m[:2], scene.bounds_max_m[:2]))
start = time.monotonic()
for ms in range(4001):
    z = scene.bounds_max_m[2] + 0.01 - 0.03 * min(ms, 4000 - ms) / 2000  # [m] down and back
    client.send_tip(1, (x, y, z))
    f = client.wait_force(1, 0.001)
    if f is not None and ms % 250 == 0:
        print(f"t {ms / 1000:.2f} s  tip z {z:.4f} m  force z {f.force_n[2]:.3f} N")
    time.sleep(max(0.0, start + (ms + 1) / 1000 - time.monotonic()))
