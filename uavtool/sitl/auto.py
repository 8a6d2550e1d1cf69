"""AUTO mode: the stored mission and its execution, item by item (ArduCopter semantics).

Item 0 is home. Navigation items (TAKEOFF, WAYPOINT, LAND, RETURN_TO_LAUNCH) run until
reached; the DO/CONDITION items between them run immediately when the mission reaches them.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from uavtool.geo import GeoPoint
from uavtool.mavlink.dialect import mavlink
from uavtool.sitl.physics import Target
from uavtool.sitl.state import AMSL_FRAMES, RELATIVE_ALT_FRAMES, MissionItem, Mode

if TYPE_CHECKING:
    from uavtool.sitl.autopilot import Autopilot

NAV_COMMANDS = frozenset(
    {
        mavlink.MAV_CMD_NAV_TAKEOFF,
        mavlink.MAV_CMD_NAV_WAYPOINT,
        mavlink.MAV_CMD_NAV_LAND,
        mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH,
    }
)
SUPPORTED_COMMANDS = NAV_COMMANDS | {
    mavlink.MAV_CMD_DO_CHANGE_SPEED,
    mavlink.MAV_CMD_CONDITION_YAW,
    mavlink.MAV_CMD_DO_MOUNT_CONTROL,
    mavlink.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
    mavlink.MAV_CMD_DO_DIGICAM_CONTROL,
}
_GLOBAL_FRAMES = RELATIVE_ALT_FRAMES | AMSL_FRAMES


class AutoMission:
    """The mission stored on the vehicle and the AUTO-mode executor."""

    def __init__(self, autopilot: Autopilot) -> None:
        self.ap = autopilot
        self.items: list[MissionItem] = []  # items[0] is home
        self.current = 0
        self.running = False
        self.reached: list[int] = []  # MISSION_ITEM_REACHED seqs not yet reported
        self.changed = False  # MISSION_CURRENT to send now
        self._hold_until_ns: int | None = None
        self._landing = False
        self._rtl_started = False

    def replace(self, items: list[MissionItem]) -> None:
        self.items = items
        self.current = 0
        self.running = False
        self.changed = True

    def has_nav_items(self) -> bool:
        return any(it.command in NAV_COMMANDS for it in self.items[1:])

    def starts_with_takeoff(self) -> bool:
        for it in self.items[1:]:
            if it.command in NAV_COMMANDS:
                return bool(it.command == mavlink.MAV_CMD_NAV_TAKEOFF)
        return False

    def landing(self) -> bool:
        return self.running and self._landing

    def land_complete(self) -> None:
        """The vehicle touched down on a NAV_LAND item: report it and finish or go on."""
        self._landing = False
        self.reached.append(self.items[self.current].seq)
        self._advance()

    def start(self) -> None:
        if self.current < 1 or self.current >= len(self.items):
            self.current = 1
        self.running = True
        self._begin(self.current)

    def stop(self) -> None:
        self.running = False
        self._landing = False

    def set_current(self, seq: int) -> bool:
        if not 0 <= seq < len(self.items):
            return False
        self.current = max(seq, 1) if len(self.items) > 1 else 0
        self.changed = True
        if self.running:
            self._begin(self.current)
        return True

    def update(self) -> None:
        """Called every physics step in AUTO."""
        if not self.running or not 1 <= self.current < len(self.items):
            return
        item = self.items[self.current]
        if self._nav_done(item):
            self.reached.append(item.seq)
            self._advance()

    def _advance(self) -> None:
        nxt = self.current + 1
        if nxt >= len(self.items):
            self.running = False  # mission complete: hold at the last position
            self.ap.say(mavlink.MAV_SEVERITY_INFO, "Mission complete")
            self.ap.vehicle.set_target(Target(yaw_deg=self.ap.vehicle.target.yaw_deg))
            return
        self.current = nxt
        self.changed = True
        self._begin(nxt)

    def _begin(self, seq: int) -> None:
        """Run DO/CONDITION items at ``seq`` onward until a nav item starts."""
        while seq < len(self.items):
            item = self.items[seq]
            self.current = seq
            self.changed = True
            if item.command in NAV_COMMANDS:
                self._start_nav(item)
                return
            self._do(item)
            self.reached.append(item.seq)
            seq += 1
        self.current = len(self.items) - 1
        self.running = False

    def _target_ned(self, item: MissionItem) -> tuple[float, float, float]:
        ap = self.ap
        n, e, d = ap.state.pos_ned_m
        if item.frame in _GLOBAL_FRAMES and (item.x or item.y):
            point = GeoPoint(item.x / 1e7, item.y / 1e7, ap.home.alt_amsl_m)
            n, e, _ = ap.ned_of(point)
        if item.frame in RELATIVE_ALT_FRAMES or item.frame not in _GLOBAL_FRAMES:
            alt_rel = item.z
        else:
            alt_rel = item.z - ap.home.alt_amsl_m
        return (n, e, -alt_rel if item.z or item.command != mavlink.MAV_CMD_NAV_LAND else d)

    def _start_nav(self, item: MissionItem) -> None:
        ap = self.ap
        self._hold_until_ns = None
        self._landing = False
        self._rtl_started = False
        cmd = item.command
        if cmd == mavlink.MAV_CMD_NAV_TAKEOFF:
            if ap.on_ground:
                ap.start_takeoff(max(item.z, 1.0))
            else:
                n, e, _ = ap.state.pos_ned_m
                ap.vehicle.set_target(Target(pos_ned_m=(n, e, -max(item.z, 1.0))))
        elif cmd == mavlink.MAV_CMD_NAV_WAYPOINT:
            yaw = item.param4 % 360.0 if math.isfinite(item.param4) and item.param4 != 0 else None
            ap.vehicle.set_target(Target(pos_ned_m=self._target_ned(item), yaw_deg=yaw, path=True))
        elif cmd == mavlink.MAV_CMD_NAV_LAND:
            n, e, _ = self._target_ned(item)
            ap.land_ne = (n, e)
            ap.vehicle.set_target(Target(pos_ned_m=(n, e, ap.state.pos_ned_m[2])))
        elif cmd == mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            self._rtl_started = True

    def _nav_done(self, item: MissionItem) -> bool:
        ap = self.ap
        s = ap.state
        cmd = item.command
        if cmd == mavlink.MAV_CMD_NAV_TAKEOFF:
            if ap.alt_rel_m() >= max(item.z, 1.0) - 0.2:
                ap.taking_off = False
                return True
            return False
        if cmd == mavlink.MAV_CMD_NAV_WAYPOINT:
            goal = ap.vehicle.target.pos_ned_m or tuple(s.pos_ned_m)
            dist = math.dist(goal, s.pos_ned_m)
            if self._hold_until_ns is None:
                # ArduCopter: the leg's S-curve has ended, and the vehicle is within the radius
                if not ap.vehicle.control.leg_done or dist > ap.params["WPNAV_RADIUS"] / 100.0:
                    return False
                self._hold_until_ns = ap.now_ns + int(max(item.param1, 0.0) * 1e9)
            return ap.now_ns >= self._hold_until_ns
        if cmd == mavlink.MAV_CMD_NAV_LAND:
            land_n, land_e = ap.land_ne
            if (
                not self._landing
                and math.hypot(land_n - s.pos_ned_m[0], land_e - s.pos_ned_m[1]) < 0.5
            ):
                self._landing = True
            if self._landing:
                ap.descend()
            return False  # finished by land_complete() on touchdown
        if cmd == mavlink.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            ap.set_mode(Mode.RTL)
            return False
        return True

    def _do(self, item: MissionItem) -> None:
        ap = self.ap
        cmd = item.command
        if cmd == mavlink.MAV_CMD_DO_CHANGE_SPEED:
            ap.change_speed(int(item.param1), item.param2)
        elif cmd == mavlink.MAV_CMD_CONDITION_YAW:
            direction = -1 if item.param3 < 0 else 1
            ap.condition_yaw(item.param1, item.param2, direction, bool(item.param4))
        elif cmd == mavlink.MAV_CMD_DO_MOUNT_CONTROL:
            ap.set_gimbal(pitch_deg=item.param1, yaw_deg=item.param3)
        elif cmd == mavlink.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW:
            flags = item.x  # MISSION_ITEM_INT carries param5 (the flags) in x
            locked = bool(flags & mavlink.GIMBAL_MANAGER_FLAGS_YAW_LOCK)
            ap.set_gimbal(pitch_deg=item.param1, yaw_deg=item.param2, yaw_locked=locked)
        elif cmd == mavlink.MAV_CMD_DO_DIGICAM_CONTROL:
            ap.shutter.trigger()
