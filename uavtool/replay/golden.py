"""Golden recordings: replayed with ``--check`` by the test suite, regenerated only by a
deliberate ``uavtool replay --update-golden``. Each golden ``X.mcap`` has a text digest
``X.outputs.txt`` beside it (one line per output, floats rounded) so that a change of
behaviour shows as a readable diff in review."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from uavtool.replay.load import RecordedOutput, is_fleet, load_fleet, load_flight
from uavtool.replay.refly import is_lockstep, refly
from uavtool.replay.replay import replay
from uavtool.replay.write import write_replay


def digest_path(recording: Path) -> Path:
    return recording.with_suffix(".outputs.txt")


def digest(outputs: list[RecordedOutput] | tuple[RecordedOutput, ...]) -> str:
    """One line per output: number, step, type and its content, floats to 4 decimals."""
    return "".join(f"{o.n:4d} {o.step:5d} {_line(o.data)}\n" for o in outputs)


def recorded_digest(recording: Path) -> str:
    """The digest of the outputs ``recording`` holds: for a fleet, each vehicle's under a
    ``## uavK`` line, in system-id order."""
    if not is_fleet(recording):
        return digest(load_flight(recording).outputs)
    fleet = load_fleet(recording)
    return "".join(f"## uav{v.sysid}\n{digest(v.outputs)}" for v in fleet.vehicles)


def _line(data: dict[str, Any]) -> str:
    kind = data.get("type")
    body = {k: v for k, v in data.items() if k != "type"}
    if kind == "Shapes":
        shapes = body.pop("shapes")
        body["shapes"] = [
            f"rgb{tuple(s['colour_rgb'])} {len(s['polygon_px'])} corners "
            f"{len(s['holes_px'])} holes area {s['area_px']:.1f}"
            for s in shapes
        ]
    elif kind == "ModelBuilt":
        body["vertices_m"] = f"{len(body['vertices_m'])} vertices"
        body["faces"] = f"{len(body['faces'])} faces"
    return f"{kind} {json.dumps(_round(body), ensure_ascii=False)}"


def _round(value: Any) -> Any:
    if isinstance(value, float):
        return round(value, 4)
    if isinstance(value, list):
        return [_round(v) for v in value]
    if isinstance(value, dict):
        return {k: _round(v) for k, v in value.items()}
    return value


def update_golden(recording: Path) -> tuple[int, int]:
    """Bring ``recording`` and its digest up to what the code does now; returns (outputs
    before, outputs after).

    A lockstep flight of the built-in vehicle is flown again from its own metadata and
    replaced whole, so that it still re-flies identically. Any other recording keeps its
    observations and gets the outputs the mission produces from them now; that refuses a
    replay that diverges. A fleet's recording is re-flown (only a lockstep one is taken)."""
    if is_fleet(recording):
        return _update_fleet(recording)
    flight = load_flight(recording)
    if is_lockstep(recording):
        _fly_again(recording)
        outputs = load_flight(recording).outputs
        digest_path(recording).write_text(digest(outputs))
        return len(flight.outputs), len(outputs)
    result = replay(flight)
    if result.divergence is not None:
        from uavtool.replay.load import ReplayInputError  # noqa: PLC0415

        raise ReplayInputError(
            f"{recording}: the mission now diverges at step {result.divergence.step} "
            f"({result.divergence.reason}); fly this golden again instead"
        )
    tmp = recording.with_suffix(".mcap.tmp")
    write_replay(
        recording, tmp, result.outputs, result.blobs, flight.params, outcome=result.outcome
    )
    tmp.replace(recording)
    digest_path(recording).write_text(digest(result.outputs))
    return len(flight.outputs), len(result.outputs)


def _update_fleet(recording: Path) -> tuple[int, int]:
    """`update_golden` of a fleet's lockstep flight: flown again and replaced whole."""
    from uavtool.replay.load import ReplayInputError  # noqa: PLC0415

    if not is_lockstep(recording):
        raise ReplayInputError(
            f"{recording}: a fleet's golden must be a lockstep flight of built-in vehicles "
            "(uavtool fly --vehicles N), which is flown again"
        )
    before = sum(len(v.outputs) for v in load_fleet(recording).vehicles)
    _fly_again(recording)
    digest_path(recording).write_text(recorded_digest(recording))
    return before, sum(len(v.outputs) for v in load_fleet(recording).vehicles)


def _fly_again(recording: Path) -> None:
    """Replace a lockstep ``recording`` whole by a flight of its own configuration again."""
    tmp = recording.with_suffix(".mcap.tmp")
    try:
        refly(recording, out=tmp, compare=False)
        tmp.replace(recording)
    finally:
        tmp.unlink(missing_ok=True)
