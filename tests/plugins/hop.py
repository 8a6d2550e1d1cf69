"""A small plug-in mission for the tests, written as a user would: the public API only."""

from __future__ import annotations

from dataclasses import dataclass, field

from uavtool.api import NADIR_DEG, FlightMission, FlightParams, Result, Wait


@dataclass(frozen=True, slots=True)
class Hop:
    altitude_m: float = 12.0
    photos: int = 2
    fail_at_photo: int = -1
    """Raise a bug (ZeroDivisionError) before this photo (−1: never)."""


@dataclass(frozen=True, slots=True)
class HopParams:
    hop: Hop = field(default_factory=Hop)
    flight: FlightParams = field(default_factory=FlightParams)


class HopMission(FlightMission):
    """Take off, take a few photos straight down, land."""

    params_type = HopParams
    params: HopParams

    def fly(self) -> Wait[str]:
        h = self.params.hop
        yield from self.arm_and_take_off(h.altitude_m)
        frames = []
        for k in range(h.photos):
            if k == h.fail_at_photo:
                frames.append(1 // 0)
            photo = yield from self.photo(f"hop-{k}", NADIR_DEG)
            frames.append(photo.frame_index)
        self.emit(Result("hop", {"frames": frames}))
        return f"{len(frames)} photos"


class NotAMission:
    """Not a FlightMission."""


class BrokenStart(HopMission):
    """Its constructor fails."""

    def __init__(self, params: HopParams, inputs: object) -> None:
        raise RuntimeError("no camera calibration file")
