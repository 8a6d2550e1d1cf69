"""Replay: the recorded observations, in order, through a fresh mission; every output compared
with the recorded one (ArduPilot's Replay works the same way: log every input, demand every
output back exactly).

With the recorded parameters the outputs must be equal bit for bit (``--check``). With other
parameters the mission may decide differently; when it would command something the recording
did not (so the recorded observations no longer answer it), the mission is stopped at that
step and replay says why. Per-frame vision is re-run on every recorded photo regardless.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from uavtool.geo import wrap_180
from uavtool.mission import FlightParams, MissionInputs, Output
from uavtool.mission.codec import encode_output, output_bytes
from uavtool.plugins import create_mission, flight_params, guarded
from uavtool.replay.load import RecordedFlight, RecordedOutput

Progress = Callable[[int, int], None]
"""Called with (observations done, total)."""

_COMMANDS = frozenset({"SetMode", "Arm", "Takeoff", "GoTo", "SetGimbal", "TakePhoto"})


@dataclass(frozen=True, slots=True)
class Difference:
    """The first place where replayed and recorded outputs differ."""

    step: int
    n: int
    kind: str
    path: str
    recorded: Any
    replayed: Any

    def describe(self) -> str:
        where = f"step {self.step}, output {self.n} ({self.kind})"
        field_ = f" field {self.path}" if self.path else ""
        return (
            f"{where}{field_}: recorded {_short(self.recorded)}, replayed {_short(self.replayed)}"
        )


@dataclass(frozen=True, slots=True)
class Divergence:
    """Where the mission's decisions left the recording, and why."""

    step: int
    reason: str


@dataclass(slots=True)
class ReplayResult:
    outputs: list[RecordedOutput] = field(default_factory=list)
    """Every replayed output (numbered like the recording's)."""
    steps: int = 0
    """Observations fed to the mission."""
    first_difference: Difference | None = None
    divergence: Divergence | None = None
    finished: bool = False
    blobs: dict[int, bytes] = field(default_factory=dict)
    """The bytes each replayed output carries (a model's GLB, a picture's PNG), by output
    number."""

    @property
    def outcome(self) -> dict[str, str] | None:
        """The replayed Outcome as an ``outcome`` metadata record (None if not reached)."""
        for out in reversed(self.outputs):
            if out.data.get("type") == "Outcome":
                return {
                    k: v if isinstance(v, str) else json.dumps(v)
                    for k, v in out.data.items()
                    if k != "type"
                }
        return None

    @property
    def identical(self) -> bool:
        return self.first_difference is None and self.divergence is None


def replay(
    flight: RecordedFlight,
    params: Any = None,
    *,
    progress: Progress | None = None,
) -> ReplayResult:
    """Feed the recorded observations to a fresh mission built with ``params`` (default: the
    recorded ones) and compare its outputs with the recording's, step by step."""
    p = params if params is not None else flight.params
    mission = create_mission(flight.mission, p, MissionInputs(target_rgb=flight.target_rgb))
    cmp = Comparison(flight.outputs, flight_params(flight.mission, p))
    total = len(flight.observations)
    cmp.emit(0, guarded(mission.start))
    for step, obs in enumerate(flight.observations, start=1):
        if mission.done:
            cmp.diverge(step, "the mission ended before the recording did")
            break
        cmp.result.steps = step
        cmp.emit(step, guarded(mission.step, obs))
        if cmp.result.divergence is not None:
            break
        if progress is not None and (step % 200 == 0 or step == total):
            progress(step, total)
    result = cmp.result
    result.finished = mission.done
    if result.identical and len(result.outputs) < len(flight.outputs) and not flight.truncated:
        cmp.missing(flight.outputs[len(result.outputs)])
    return result


class Comparison:
    """Positional comparison of all outputs (for ``--check``), and of the commands alone (to
    find where the mission's decisions leave the recording)."""

    def __init__(self, recorded: tuple[RecordedOutput, ...], flight: FlightParams) -> None:
        self.result = ReplayResult()
        self._radius_m = flight.arrive_radius_m
        self._heading_deg = flight.heading_tolerance_deg
        self._recorded = iter(recorded)
        self._commands = iter([r for r in recorded if r.data.get("type") in _COMMANDS])

    def missing(self, recorded: RecordedOutput) -> None:
        """The recording has this output, and the replay ended before making it."""
        self.result.first_difference = Difference(
            recorded.step, recorded.n, str(recorded.data.get("type")), "", recorded.data, "nothing"
        )

    def diverge(self, step: int, reason: str) -> None:
        if self.result.divergence is None:
            self.result.divergence = Divergence(step, reason)

    def emit(self, step: int, outputs: list[Output]) -> None:
        for out in outputs:
            data = encode_output(out)
            n = len(self.result.outputs) + 1
            self.result.outputs.append(RecordedOutput(n, step, data))
            blob = output_bytes(out)
            if blob is not None:
                self.result.blobs[n] = blob
            if self.result.first_difference is None:
                self._check(step, n, data, next(self._recorded, None))
            if data["type"] in _COMMANDS and self.result.divergence is None:
                expected = next(self._commands, None)
                if expected is None or not self._same_decision(expected.data, data):
                    self.diverge(step, _why(expected, data))

    def _same_decision(self, recorded: dict[str, Any], replayed: dict[str, Any]) -> bool:
        """The same command, or a move to within the arrival tolerances of the recorded one:
        the recorded observations still answer it."""
        if _first_diff(recorded, replayed)[0] is None:
            return True
        if recorded.get("type") != "GoTo" or replayed.get("type") != "GoTo":
            return False
        a, b = recorded.get("heading_deg"), replayed.get("heading_deg")
        try:  # the recorded side is read from a file: any type may stand there
            if (a is None) != (b is None) or (
                a is not None and abs(wrap_180(a - b)) > self._heading_deg
            ):
                return False
            return bool(math.dist(recorded["pos_enu_m"], replayed["pos_enu_m"]) <= self._radius_m)
        except (KeyError, TypeError, ValueError):
            return False

    def _check(
        self, step: int, n: int, data: dict[str, Any], expected: RecordedOutput | None
    ) -> None:
        kind = str(data["type"])
        if expected is None:
            self.result.first_difference = Difference(step, n, kind, "", "nothing", data)
        elif expected.step != step:
            self.result.first_difference = Difference(step, n, kind, "step", expected.step, step)
        else:
            path, a, b = _first_diff(expected.data, data)
            if path is not None:
                self.result.first_difference = Difference(step, n, kind, path, a, b)


def _why(expected: RecordedOutput | None, data: dict[str, Any]) -> str:
    if expected is None:
        return f"the mission would send {_short(data)}, which the recording never did"
    if expected.data.get("type") != data.get("type"):
        return (
            f"the mission would send {_short(data)} where the recording has "
            f"{_short(expected.data)}; the recorded observations no longer answer it"
        )
    return (
        f"the mission would send {_short(data)} instead of the recorded {_short(expected.data)}; "
        "no photo was taken there"
    )


def _first_diff(a: Any, b: Any, path: str = "") -> tuple[str | None, Any, Any]:
    """The dotted path of the first difference between two JSON trees (floats compared
    exactly), or (None, …) when equal."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in list(a) + [k for k in b if k not in a]:
            if key not in a or key not in b:
                return f"{path}.{key}".lstrip("."), a.get(key, "<absent>"), b.get(key, "<absent>")
            found = _first_diff(a[key], b[key], f"{path}.{key}")
            if found[0] is not None:
                return found
        return None, None, None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{path}.length".lstrip("."), len(a), len(b)
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _first_diff(x, y, f"{path}[{i}]")
            if found[0] is not None:
                return found
        return None, None, None
    if type(a) is not type(b) and not (isinstance(a, (int, float)) and isinstance(b, (int, float))):
        return path.lstrip(".") or "value", a, b
    return (None, None, None) if a == b else (path.lstrip(".") or "value", a, b)


def _short(value: Any, limit: int = 120) -> str:
    if isinstance(value, dict) and "type" in value:
        body = ", ".join(f"{k}={_short(v, 40)}" for k, v in value.items() if k != "type")
        text = f"{value['type']}({body})"
    else:
        text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"
