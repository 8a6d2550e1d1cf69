"""Your vision on recorded frames: ``replay REC --vision module:function`` writes the
function's detections beside the original's channels, for Foxglove, Lichtblick and Rerun."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
from click.testing import CliRunner
from foxglove_schemas_protobuf.ImageAnnotations_pb2 import ImageAnnotations

from uavtool.cli import cli
from uavtool.recording import RecordingReader, summarize

GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"


def _run(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, list(args))
    return result.exit_code, result.output


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    with RecordingReader(path) as reader:
        return [(m.channel.topic, m.log_time_ns, m.data) for m in reader.messages()]


def test_detections_are_written_beside_the_original(tmp_path: Path) -> None:
    out = tmp_path / "detected.mcap"
    code, text = _run("replay", str(GOLDEN), "--vision", "tests.plugins.detector:red_roofs",
                      "--output", str(out))  # fmt: skip
    assert code == 0, text
    assert "on 7 photos: 7 detections" in text
    before, after = _messages(GOLDEN), _messages(out)
    kept = [m for m in after if not m[0].startswith("/vision/")]
    assert kept == before  # every original message, unchanged and in order
    with RecordingReader(out) as reader:
        meta = dict(reader.metadata)
        schema = json.loads(
            next(
                reader.schemas[c.schema_id].data
                for c in reader.channels.values()
                if c.topic == "/vision/detections"
            )
        )
        found = [e.value.payload for e in reader.entries(["/vision/detections"])]
        images = {e.log_time_ns for e in reader.entries(["/camera/image"])}
    assert meta["vision"] == {"function": "tests.plugins.detector:red_roofs", "source": GOLDEN.name}
    assert len(found) == 7 and sum(len(f["detections"]) for f in found) == 7
    for payload in found:
        jsonschema.validate(payload, schema)  # a standard validator accepts every message
    annotations = [(t, d) for topic, t, d in after if topic == "/vision/annotations"]
    assert {t for t, _ in annotations} == images  # stamped like the frame they belong to
    for (t, data), payload in zip(annotations, found, strict=True):
        pb = ImageAnnotations.FromString(data)
        assert (pb.points and len(pb.points) == 3 * len(payload["detections"])) or not pb.points
        for det in payload["detections"]:
            x0, y0, x1, y1 = det["box_px"]
            box = pb.points[0]
            assert [(p.x, p.y) for p in box.points] == [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
            assert box.timestamp.seconds * 10**9 + box.timestamp.nanos == t
            assert pb.texts[0].text.startswith("red roof 0.")
    shown = CliRunner().invoke(cli, ["view", str(out), "--save", str(tmp_path / "d.rrd")])
    assert shown.exit_code == 0 and "7 detections" in shown.output, shown.output


def test_a_fleets_detections_go_under_each_vehicle(tmp_path: Path) -> None:
    """In a fleet's recording each frame is its vehicle's (``Frame.vehicle``, its frame index
    and pose), and its detections go under that vehicle's topics, stamped like its frame."""
    fleet = GOLDEN.with_name("fleet-search.mcap")
    out = tmp_path / "detected.mcap"
    code, text = _run("replay", str(fleet), "--vision", "tests.plugins.detector:vehicles",
                      "--output", str(out))  # fmt: skip
    assert code == 0, text
    written = _messages(out)
    with RecordingReader(out) as reader:
        topics = set(reader.topics())
        assert "/vision/detections" not in topics
        for k in (1, 2, 3):
            images = [e.log_time_ns for e in reader.entries([f"/uav{k}/camera/image"])]
            found = list(reader.entries([f"/uav{k}/vision/detections"]))
            marks = [t for topic, t, _ in written if topic == f"/uav{k}/vision/annotations"]
            assert [e.log_time_ns for e in found] == images == marks
            labels = {d["label"] for e in found for d in e.value.payload["detections"]}
            assert labels == {f"vehicle {k}"}
            indices = [e.value.payload["frame_index"] for e in found]
            assert indices == list(range(len(images)))  # each vehicle's own numbering
    assert f"on {summarize(fleet).frame_count} photos" in text, text


@pytest.mark.parametrize(
    ("function", "code", "words"),
    [
        ("tests.plugins.detector:dicts", 1, "returned a dict, expected uavtool.api.Detection"),
        ("tests.plugins.detector:raises", 1, "on frame 3 (top) raised ValueError: model weights"),
        ("tests.plugins.detector:nosuch", 2, "tests.plugins.detector has no function nosuch"),
        ("no_module_here:f", 2, "cannot import no_module_here"),
        ("not a spec", 2, "expected module:function"),
    ],
)
def test_a_broken_function_writes_nothing(
    tmp_path: Path, function: str, code: int, words: str
) -> None:
    out = tmp_path / "out.mcap"
    exit_code, text = _run("replay", str(GOLDEN), "--vision", function, "--output", str(out))
    assert exit_code == code, text
    assert words in text and "Traceback" not in text and len(text.strip().splitlines()) == 1
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_a_folder_on_dask_with_a_function_from_the_current_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """As uvicorn finds ``main:app``: the module in the current folder, in every worker too."""
    work = tmp_path / "work"
    work.mkdir()
    detector = Path(__file__).with_name("detector.py").read_text()
    (work / "my_vision.py").write_text(detector)
    monkeypatch.chdir(work)
    golden = GOLDEN.parent
    out = tmp_path / "out"
    code, text = _run(
        "replay", str(golden), "--vision", "my_vision:red_roofs", "--output", str(out),
        "--workers", "1", "-q",
    )  # fmt: skip
    assert code == 0, text
    n = len(list(golden.glob("*.mcap")))
    photos = sum(summarize(p).frame_count for p in golden.glob("*.mcap"))  # a fleet's: all
    assert f"recordings     {n} of {n}" in text and f"on {photos} photos" in text, text
    written = sorted(p.name for p in out.glob("*.vision.mcap"))
    assert written == sorted(f"{p.stem}.vision.mcap" for p in golden.glob("*.mcap"))
    assert (out / "vision.parquet").exists()
