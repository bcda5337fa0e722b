import enum
from typing import List, Optional, Sequence

import numpy as np
import numpy.typing as npt

class ServerState(enum.Enum):
    waiting = ...
    alive = ...
    lost = ...

class Instrument:
    instrument_id: int
    grasper: bool
    tip_radius_m: float
    owner_client_id: int

class Material:
    name: str
    youngs_modulus_pa: float
    poisson_ratio: float
    density_kg_m3: float
    shear_q: float
    damping_per_s: float

class RequestOutcome:
    accepted: bool
    message: str
    action: str
    def __bool__(self) -> bool: ...

class Scene:
    name: str
    physics_rate_hz: float
    paused: bool
    instruments: List[Instrument]
    bounds_min_m: List[float]
    bounds_max_m: List[float]
    generation: int
    material: Material
    available_scenes: List[str]
    preparing: str
    unreadable_scenes: List[str]

class Force:
    instrument_id: int
    command_seq: int
    force_n: List[float]
    torque_n_m: List[float]
    in_contact: bool
    contact_point_m: List[float]
    contact_normal: List[float]
    penetration_m: float
    tick: int
    server_stamp_ns: int
    max_edge_strain: float

class Event:
    kind: str
    reason: str
    source_client_id: int
    instrument_id: int
    client_id: int
    sim_time_s: float
    stamp_ns: int
    text: str
    tick: int
    scene: str

class Telemetry:
    steps: int
    physics_rate_hz: float
    step_p99_us: float
    late_ticks: int
    missed_slots: int
    rejected_messages: int

class SurfaceTopology:
    mesh_id: int
    organ_name: str
    vertex_count: int
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    @property
    def rest_positions(self) -> npt.NDArray[np.float32]: ...

class MeshFrame:
    mesh_id: int
    frame: int
    sim_time_s: float
    tick: int
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...

class ClaimResult:
    claimed: bool
    why: str
    def __bool__(self) -> bool: ...

class LatencyStats:
    samples: int
    p50_us: float
    p99_us: float
    max_us: float

class Client:
    def __init__(self, domain_id: int, client_id: int, partition: str = ...) -> None: ...
    @property
    def client_id(self) -> int: ...
    def wait_for_scene(self, timeout_s: float) -> Optional[Scene]: ...
    def scene(self) -> Optional[Scene]: ...
    def claim(self, instrument_id: int, timeout_s: float = ...) -> ClaimResult: ...
    def release(self, instrument_id: int) -> None: ...
    def pause(self, timeout_s: float = ...) -> bool: ...
    def resume(self, timeout_s: float = ...) -> bool: ...
    def reset(self, timeout_s: float = ...) -> bool: ...
    def load_scene(self, name: str, timeout_s: float = ..., seed: Optional[int] = ...) -> Optional[RequestOutcome]: ...
    def set_material(
        self,
        *,
        youngs_modulus_pa: Optional[float] = ...,
        poisson_ratio: Optional[float] = ...,
        density_kg_m3: Optional[float] = ...,
        shear_q: Optional[float] = ...,
        damping_per_s: Optional[float] = ...,
        file_text: Optional[str] = ...,
        file_name: str = ...,
        timeout_s: float = ...,
    ) -> Optional[RequestOutcome]: ...
    def set_physics_rate(self, rate_hz: float, timeout_s: float = ...) -> Optional[RequestOutcome]: ...
    def take_over(self, instrument_id: int, timeout_s: float = ...) -> Optional[RequestOutcome]: ...
    def hand_back(self, instrument_id: int, timeout_s: float = ...) -> Optional[RequestOutcome]: ...
    def send_tip(self, instrument_id: int, tip_m: Sequence[float], jaw_opening_rad: float = ..., buttons: int = ...) -> None: ...
    def poll_force(self, instrument_id: int) -> Optional[Force]: ...
    def wait_force(self, instrument_id: int, timeout_s: float = ...) -> Optional[Force]: ...
    def round_trip(self) -> LatencyStats: ...
    def surface(self) -> Optional[SurfaceTopology]: ...
    def poll_mesh_frame(self) -> Optional[MeshFrame]: ...
    @property
    def mesh_frames_received(self) -> int: ...
    def poll_events(self) -> List[Event]: ...
    def poll_telemetry(self) -> List[Telemetry]: ...
    def annotate(self, text: str) -> None: ...
    @property
    def server_state(self) -> ServerState: ...
    @property
    def rejected(self) -> int: ...
    @property
    def last_rejection(self) -> str: ...

def now_ns() -> int: ...
