"""A scripted vehicle for the mission tests, in pure Python (no network, no SITL).

:class:`FakeVehicle` holds a position, heading, mode, arming state and gimbal; it moves
toward its target at fixed rates every 100 ms tick of vehicle time, answers commands as the
runner turns COMMAND_ACKs into :class:`CommandResult` (or refuses them, or leaves them
unanswered, as configured) and renders photos of its scene at the camera's pose. Its home
is the scene's origin, so the vehicle's ENU frame is the scene's. The runner's side (the
loop, timeouts, link outages) is :mod:`tests.mission.driver`.
"""

from __future__ import annotations

import math

from uavtool.camera import CameraPose, Intrinsics
from uavtool.geo import wrap_180
from uavtool.mission import (
    Arm,
    Command,
    CommandResult,
    GoTo,
    Observation,
    Photo,
    SetGimbal,
    SetMode,
    Takeoff,
    TakePhoto,
    Telemetry,
)
from uavtool.world import Scene, render

TICK_MS = 100
REFUSED = "refused (MAV_RESULT_TEMPORARILY_REJECTED)"
DENIED = "refused (MAV_RESULT_DENIED)"
INTRINSICS = Intrinsics.from_hfov(width_px=640, height_px=480, hfov_deg=60.0)

Vec3 = tuple[float, float, float]


def command_key(cmd: Command) -> str:
    """How ``refuse``/``ignore`` name a command: its class, ``SetMode:RTL`` for modes."""
    name = type(cmd).__name__
    return f"{name}:{cmd.mode}" if isinstance(cmd, SetMode) else name


class FakeVehicle:
    """An ArduCopter-like vehicle reduced to what the mission observes.

    ``refuse`` / ``ignore``: command key (see :func:`command_key`; ``SetMode`` matches every
    mode) → how many of those commands to refuse for now / leave unanswered before behaving.
    ``deny``: command keys refused for good (``MAV_RESULT_DENIED``, a final answer).
    ``stuck``: GoTo targets are taken but the vehicle never moves toward them.
    ``airborne``: start there, armed and in LOITER, instead of on the ground at home.
    ``disarm_on_ground_s``: armed and still at ground level that long, it disarms itself (PX4's
    ``COM_DISARM_PRFLT``, ArduCopter's ``DISARM_DELAY``).
    Rates: horizontal ``speed_m_s``, vertical ``climb_m_s``, yaw and gimbal in degrees/s.
    """

    def __init__(
        self,
        scene: Scene,
        *,
        intrinsics: Intrinsics = INTRINSICS,
        speed_m_s: float = 6.0,
        climb_m_s: float = 3.0,
        yaw_rate_deg_s: float = 90.0,
        gimbal_rate_deg_s: float = 90.0,
        rtl_alt_m: float = 15.0,
        refuse: dict[str, int] | None = None,
        ignore: dict[str, int] | None = None,
        deny: frozenset[str] = frozenset(),
        stuck: bool = False,
        airborne: Vec3 | None = None,
        disarm_on_ground_s: float | None = None,
    ) -> None:
        self.scene = scene
        self.intrinsics = intrinsics
        self.speed_m_s = speed_m_s
        self.climb_m_s = climb_m_s
        self.yaw_rate_deg_s = yaw_rate_deg_s
        self.gimbal_rate_deg_s = gimbal_rate_deg_s
        self.rtl_alt_m = rtl_alt_m
        self.refuse = dict(refuse or {})
        self.ignore = dict(ignore or {})
        self.deny = deny
        self.stuck = stuck
        self.time_ms = 0
        self.pos: Vec3 = (0.0, 0.0, 0.0)
        self.vel: Vec3 = (0.0, 0.0, 0.0)
        self.heading_deg = scene.home_heading_deg % 360.0
        self.mode = "STABILIZE"
        self.armed = False
        self.landed = True
        self.gimbal_pitch_deg = 0.0
        self.gimbal_yaw_deg = 0.0
        self.goal: Vec3 | None = None  # GUIDED position target
        self.goal_heading_deg: float | None = None
        self.goal_pitch_deg = 0.0
        self.rtl_cruise_m = rtl_alt_m
        if airborne is not None:  # already flying, as a pilot left it
            self.pos, self.mode, self.armed, self.landed = airborne, "LOITER", True, False
        self.disarm_on_ground_s = disarm_on_ground_s
        self._on_ground_armed_ms = 0
        self.frames = 0
        self.received: list[Command] = []  # every command that reached the vehicle

    # --- what the vehicle says ------------------------------------------------------------

    def telemetry(self) -> Telemetry:
        return Telemetry(
            time_boot_ms=self.time_ms,
            pos_enu_m=self.pos,
            vel_enu_m_s=self.vel,
            heading_deg=self.heading_deg % 360.0,
            mode=self.mode,
            armed=self.armed,
            landed=self.landed,
            gimbal_pitch_deg=self.gimbal_pitch_deg,
            gimbal_yaw_deg=self.gimbal_yaw_deg,
            battery_pct=100,
        )

    def photo(self, cmd: TakePhoto) -> Photo:
        """The scene rendered at the camera's pose now (the runner's sim camera)."""
        pose = CameraPose.from_vehicle(
            pos_enu_m=self.pos,
            vehicle_heading_deg=self.heading_deg,
            gimbal_pitch_deg=self.gimbal_pitch_deg,
            gimbal_yaw_deg=self.gimbal_yaw_deg,
        )
        image = render(self.scene, pose, self.intrinsics)
        photo = Photo(cmd.id, self.frames, cmd.tag, self.time_ms, pose, self.intrinsics, image)
        self.frames += 1
        return photo

    # --- commands -------------------------------------------------------------------------

    def execute(self, cmd: Command) -> Observation | None:
        """Act on a command; its answer (None: no COMMAND_ACK will ever come)."""
        self.received.append(cmd)
        if isinstance(cmd, TakePhoto):
            return self.photo(cmd)
        if isinstance(cmd, GoTo):  # a position target has no ACK: the runner says "sent"
            if self.mode == "GUIDED" and self.armed and not self.landed and not self.stuck:
                self.goal = cmd.pos_enu_m
                self.goal_heading_deg = cmd.heading_deg
            return CommandResult(cmd.id, True, "sent")
        if command_key(cmd) in self.deny or type(cmd).__name__ in self.deny:
            return CommandResult(cmd.id, False, DENIED, final=True)
        for table in (self.ignore, self.refuse):
            key = next((k for k in (command_key(cmd), type(cmd).__name__) if table.get(k)), None)
            if key is not None:
                table[key] -= 1
                return None if table is self.ignore else CommandResult(cmd.id, False, REFUSED)
        ok = self._apply(cmd)
        return CommandResult(cmd.id, ok, "" if ok else "refused (MAV_RESULT_FAILED)")

    def _apply(self, cmd: Command) -> bool:
        if isinstance(cmd, SetMode):
            self.set_mode(cmd.mode)
            return True
        if isinstance(cmd, Arm):
            if self.landed:
                self.armed = True
            return True
        if isinstance(cmd, Takeoff):
            if self.mode != "GUIDED" or not self.armed or not self.landed:
                return False
            self.landed = False
            self.goal = (self.pos[0], self.pos[1], cmd.alt_m)
            return True
        if isinstance(cmd, SetGimbal):
            self.goal_pitch_deg = cmd.pitch_deg
            self.gimbal_yaw_deg = cmd.yaw_deg
            return True
        raise TypeError(f"not a vehicle command: {cmd!r}")

    def set_mode(self, mode: str) -> None:
        """A mode change (the mission's, the pilot's or the failsafe's)."""
        self.mode = mode
        self.goal = None if self.landed else self.pos  # GUIDED holds until told otherwise
        self.goal_heading_deg = None
        self.rtl_cruise_m = max(self.rtl_alt_m, self.pos[2])

    # --- physics --------------------------------------------------------------------------

    def tick(self) -> None:
        """Advance 100 ms of vehicle time."""
        dt = TICK_MS / 1000.0
        self.time_ms += TICK_MS
        old = self.pos
        goal = self._target()
        if goal is not None and self.armed and not self.landed:
            self.pos = self._toward(goal, dt)
        x, y, z = self.pos
        self.vel = ((x - old[0]) / dt, (y - old[1]) / dt, (z - old[2]) / dt)
        if self.goal_heading_deg is not None and self.mode == "GUIDED":
            turn = wrap_180(self.goal_heading_deg - self.heading_deg)
            limit = self.yaw_rate_deg_s * dt
            self.heading_deg = (self.heading_deg + max(-limit, min(limit, turn))) % 360.0
        turn = self.goal_pitch_deg - self.gimbal_pitch_deg
        limit = self.gimbal_rate_deg_s * dt
        self.gimbal_pitch_deg += max(-limit, min(limit, turn))
        if self.armed and self.pos[2] <= 0.0 and self.mode in ("RTL", "LAND"):
            self.landed, self.armed = True, False  # on the ground: ArduCopter lands and disarms
        self._on_ground_armed_ms = (
            self._on_ground_armed_ms + TICK_MS if self.armed and self.pos[2] <= 0.0 else 0
        )
        if (
            self.disarm_on_ground_s is not None
            and self._on_ground_armed_ms >= self.disarm_on_ground_s * 1000.0
        ):
            self.landed, self.armed = True, False

    def _target(self) -> Vec3 | None:
        x, y, z = self.pos
        if self.mode == "GUIDED":
            return self.goal
        if self.mode == "LAND":
            return (x, y, 0.0)
        if self.mode == "RTL":
            if math.hypot(x, y) > 0.01:
                if z < self.rtl_cruise_m - 0.01:
                    return (x, y, self.rtl_cruise_m)  # climb first, then come home
                return (0.0, 0.0, z)
            return (0.0, 0.0, 0.0)
        return None  # LOITER and the rest: hold

    def _toward(self, goal: Vec3, dt: float) -> Vec3:
        x, y, z = self.pos
        dx, dy, dz = goal[0] - x, goal[1] - y, goal[2] - z
        d = math.hypot(dx, dy)
        step = self.speed_m_s * dt
        if d <= step:
            nx, ny = goal[0], goal[1]
        else:
            nx, ny = x + dx * step / d, y + dy * step / d
        climb = self.climb_m_s * dt
        nz = goal[2] if abs(dz) <= climb else z + math.copysign(climb, dz)
        return (nx, ny, max(nz, 0.0))
