# SPDX-License-Identifier: Apache-2.0
"""A client of a running viscera-server over DDS (the C++ client SDK).

    client = viscera.session.Client(domain_id=0, client_id=42)
    scene = client.wait_for_scene(5.0)
    if client.claim(1):
        client.send_tip(1, [0.0, 0.0, 0.05])
        force = client.wait_force(1, 0.01)

Calls that wait release the interpreter lock, so other Python threads run meanwhile. No Python
code runs on DDS's threads: states, forces, frames and events are polled, never pushed into
callbacks, so a DDS thread never waits for the interpreter. Surface frames' ``positions`` are
read-only numpy views of the received frame (no copy), valid as long as any view of it lives.
"""

from ._viscera.session import (
    ClaimResult,
    Client,
    Event,
    Force,
    Instrument,
    LatencyStats,
    Material,
    MeshFrame,
    RequestOutcome,
    Scene,
    ServerState,
    SurfaceTopology,
    Telemetry,
    TickPhase,
    now_ns,
)

__all__ = [
    "ClaimResult",
    "Client",
    "Event",
    "Force",
    "Instrument",
    "LatencyStats",
    "Material",
    "MeshFrame",
    "RequestOutcome",
    "Scene",
    "ServerState",
    "SurfaceTopology",
    "Telemetry",
    "TickPhase",
    "now_ns",
]
