"""uavtool replay: exact re-runs, readable first differences, bad recordings."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.recording import CompressedImage, RecordingReader
from uavtool.recording.topics import IMAGE, OUTPUTS
from uavtool.replay import ReplayInputError, load_flight, reanalyse_frames, replay
from uavtool.replay.write import write_replay
from uavtool.runner.fly import FlyConfig, fly
from uavtool.world.hard import generate_hard_scene

GOLDEN = Path(__file__).resolve().parents[2] / "recordings" / "golden"
PAPER = GOLDEN / "paper.mcap"


def run(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.output


def test_check_passes_on_the_paper_golden() -> None:
    code, out = run("replay", "--check", "-q", str(PAPER))
    assert code == 0, out
    assert "identical" in out


def test_changed_parameter_fails_check_with_first_difference() -> None:
    code, out = run("replay", "--check", "-q", str(PAPER), "--set", "recognize.threshold=0.995")
    assert code == 1
    # The first difference names the step, the output, the field, and both values.
    assert "first difference: step" in out
    assert "(Recognition) field matched: recorded True, replayed False" in out
    # The mission decides differently there: replay says where and why, and goes on with
    # per-frame vision on every recorded frame.
    assert "diverged at step" in out
    assert "decision match → no match" in out


def test_vision_parameter_change_is_reported_per_frame() -> None:
    # the overview's roofs: red 9,802 px, yellow 9,605, purple and blue ~8,490
    code, out = run("replay", "-q", str(PAPER), "--set", "vectorize.min_area_px=9700")
    assert code == 0
    assert "frame 0 (overview): shapes 4 → 1" in out  # only the red roof is large enough
    assert "diverged at step" in out  # it now flies straight to the red building


def test_unknown_parameter_lists_the_valid_ones() -> None:
    code, out = run("replay", str(PAPER), "--set", "vision.rdp_epsilon=2")
    assert code == 2
    assert "unknown parameter 'vision.rdp_epsilon'" in out
    assert "vectorize.rdp_epsilon_px" in out


def test_params_file(tmp_path: Path) -> None:
    params = tmp_path / "p.json"
    params.write_text(json.dumps({"recognize": {"threshold": 0.995}}))
    code, out = run("replay", "-q", str(PAPER), "--set-file", str(params))
    assert code == 0
    assert "diverged" in out


def test_out_writes_a_recording_that_replays_identically(tmp_path: Path) -> None:
    out = tmp_path / "replayed.mcap"
    code, text = run("replay", "-q", str(PAPER), "--output", str(out))
    assert code == 0, text
    original = load_flight(PAPER)
    copy = load_flight(out)
    from uavtool.mission.codec import encode_observation

    assert [encode_observation(o) for o in copy.observations] == [
        encode_observation(o) for o in original.observations
    ]
    assert [o.data for o in copy.outputs] == [o.data for o in original.outputs]
    assert replay(copy).identical


def test_other_tool_version_with_same_behaviour_passes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import uavtool.recording.writer as writer_module

    monkeypatch.setattr(writer_module, "__version__", "0.0.1-older")
    old = tmp_path / "old.mcap"
    flight = load_flight(PAPER)
    result = replay(flight)
    write_replay(PAPER, old, result.outputs, result.blobs, flight.params, outcome=result.outcome)
    assert load_flight(old).tool_version == "0.0.1-older"
    code, out = run("replay", "--check", "-q", str(old))
    assert code == 0, out


def test_truncated_golden_is_a_clear_error(tmp_path: Path) -> None:
    cut = tmp_path / "cut.mcap"
    data = PAPER.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    code, out = run("replay", "--check", "-q", str(cut))
    assert code == 2
    assert "truncated" in out and "--recover" in out
    assert "Traceback" not in out


def test_corrupt_file_is_a_clear_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"this is not a recording" * 10)
    code, out = run("replay", "--check", str(bad))
    assert code == 2
    assert str(bad) in out
    assert "Traceback" not in out


def test_not_a_mission_recording(tmp_path: Path) -> None:
    from uavtool.recording import RecordingWriter

    path = tmp_path / "plain.mcap"
    with RecordingWriter(path):
        pass
    code, out = run("replay", str(path))
    assert code == 2
    assert "not a mission recording" in out


def test_missing_frames_are_named(tmp_path: Path) -> None:
    """A recording whose camera frames were dropped says which frame is missing."""
    from uavtool.recording import RecordingWriter

    src = PAPER
    dst = tmp_path / "no_frames.mcap"
    with RecordingReader(src) as reader:
        meta = {n: r for n, r in reader.metadata if n != "uavtool"}
        with RecordingWriter(dst, metadata=meta) as w:
            from uavtool.recording.topics import OBSERVATIONS, TARGET

            for topic, schema in (
                (OBSERVATIONS, "uavtool.Observation"),
                (OUTPUTS, "uavtool.Output"),
            ):
                w.add_json_topic(topic, schema_name=schema, schema={"type": "object"})
            kept = 0
            for e in reader.entries([TARGET, IMAGE, OBSERVATIONS]):
                if e.topic == IMAGE:
                    kept += 1
                    if kept > 2:
                        continue  # keep frames 0 and 1 only
                if isinstance(e.value, CompressedImage):
                    w.write(e.topic, e.value, log_time_ns=e.log_time_ns)
                else:
                    w.write_json(e.topic, e.value.payload, log_time_ns=e.log_time_ns)  # type: ignore[union-attr]
    with pytest.raises(
        ReplayInputError, match=r"photo frame 2 \(step \d+\) is missing from /camera/image"
    ):
        load_flight(dst)


@pytest.mark.slow
def test_replay_is_deterministic_across_processes_and_never_renders(tmp_path: Path) -> None:
    """Two fresh interpreters, with the renderer made unimportable, give identical outputs."""
    script = (
        "import sys, json\n"
        "sys.modules['uavtool.world'] = None  # replay must not need the renderer or the scene\n"
        "from uavtool.replay import load_flight, replay\n"
        "r = replay(load_flight(sys.argv[1]))\n"
        "assert r.identical, r.first_difference\n"
        "print(json.dumps([o.data for o in r.outputs], sort_keys=True))\n"
    )
    outs = [
        subprocess.run(
            [sys.executable, "-c", script, str(PAPER)], capture_output=True, text=True, check=True
        ).stdout
        for _ in range(2)
    ]
    assert outs[0] == outs[1]
    assert len(json.loads(outs[0])) == len(load_flight(PAPER).outputs)


def test_copy_of_golden_keeps_path_independent(tmp_path: Path) -> None:
    """Replay depends only on the file: a copy elsewhere replays the same."""
    copy = tmp_path / "elsewhere.mcap"
    shutil.copy(PAPER, copy)
    assert replay(load_flight(copy)).identical


@pytest.mark.parametrize("seed", [2, 53])
def test_per_frame_reanalysis_with_the_recorded_parameters_changes_nothing(
    seed: int, tmp_path: Path
) -> None:
    """Hard scenes flown on the built-in vehicle. Scene 53: a look aimed at a pink building
    has a larger teal one as near the photo's centre; judged by the colour it was aimed at
    (the point of interest's, from the recorded plan) it is the match it was in flight.
    Scene 2: the photo taken to measure a roof ("poi-9-roof") is not a look and is not
    judged."""
    rec = tmp_path / "hard.mcap"
    fly(FlyConfig(scene=generate_hard_scene(seed=seed), record=rec))
    flight = load_flight(rec)
    changes = reanalyse_frames(flight, flight.params)
    assert [c.describe() for c in changes if c.changed] == []
    assert any(c.matched_after for c in changes)


def test_vision_only_says_which_shape_it_judged_and_the_best_in_the_frame() -> None:
    """The issue's case: a photo whose aimed-at shape scores 0.194 while another shape in it
    (what `uavtool vision match` finds) scores 0.876."""
    from uavtool.replay.frames import FrameChange

    line = FrameChange(4, "poi-3", 2, 2, 0.194, 0.194, False, False, 0.876).describe()
    assert "match score of the aimed-at shape 0.194 → 0.194" in line
    assert "best shape in the frame 0.876" in line
    same = FrameChange(4, "poi-3", 2, 2, 0.9, 0.9, True, True, 0.9).describe()
    assert "best shape" not in same
