from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
from click.testing import CliRunner

from uavtool.camera import CameraPose, Intrinsics
from uavtool.cli import cli
from uavtool.vision.io import views_to_json
from uavtool.world import load_scene, render

from .synth import draw, family_shape, place

RED = (210, 40, 40)
BLUE = (40, 90, 220)


def _write(path: Path, rgb: np.ndarray) -> Path:
    cv2.imwrite(str(path), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    return path


def test_every_vision_command_has_an_example() -> None:
    runner = CliRunner()
    for args in (["vision"], ["vision", "vectorize"], ["vision", "match"], ["vision", "model"]):
        result = runner.invoke(cli, [*args, "--help"])
        assert result.exit_code == 0
        assert "Example:" in result.output or "Examples:" in result.output


def test_vectorize_writes_shapes_and_overlay(tmp_path: Path) -> None:
    ell = place(family_shape("L", 0.7, 0.35), angle_deg=20, size_px=200, centre=(320, 240))
    frame = _write(tmp_path / "frame.png", draw([(ell, RED)]))
    out, overlay = tmp_path / "shapes.json", tmp_path / "overlay.png"
    result = CliRunner().invoke(
        cli, ["vision", "vectorize", str(frame), "-o", str(out), "--overlay", str(overlay)]
    )
    assert result.exit_code == 0, result.output
    assert "6 corners" in result.output
    assert len(json.loads(out.read_text())["shapes"]) == 1
    assert cv2.imread(str(overlay)).shape == (960, 1280, 3)


def _l_target(tmp_path: Path, ell: np.ndarray) -> Path:
    """The target picture: the L in red, flat (one shade), upright in the middle."""
    return _write(
        tmp_path / "target.png",
        draw([(place(ell, angle_deg=0, size_px=150, centre=(320, 240)), RED)], shade=False),
    )


def test_match_finds_the_target_and_fails_when_absent(tmp_path: Path) -> None:
    # Flat roofs (one shade each): `match` compares the brightest shade of each colour.
    ell = family_shape("L", 0.6, 0.3)
    target = _l_target(tmp_path, ell)
    frame = _write(
        tmp_path / "frame.png",
        draw(
            [
                (
                    place(
                        family_shape("U", 0.8, 0.35), angle_deg=10, size_px=120, centre=(150, 150)
                    ),
                    BLUE,
                ),
                (place(ell, angle_deg=75, size_px=180, centre=(450, 300)), RED),
            ],
            shade=False,
        ),
    )
    runner = CliRunner()
    result = runner.invoke(cli, ["vision", "match", str(target), str(frame)])
    assert result.exit_code == 0, result.output
    assert "best: shape 1" in result.output
    assert result.output.count("  judgeable") == 2 and "NOT judgeable" not in result.output
    other = _write(
        tmp_path / "other.png",
        draw(
            [
                (
                    place(
                        family_shape("U", 0.8, 0.35), angle_deg=0, size_px=150, centre=(320, 240)
                    ),
                    BLUE,
                )
            ]
        ),
    )
    result = runner.invoke(cli, ["vision", "match", str(target), str(other)])
    assert result.exit_code == 1
    assert f"uavtool: error: {other}: no shape matches the target" in result.output
    assert "the best, shape 0, scores 0." in result.output


def test_match_says_a_target_cut_by_the_border_is_not_judgeable(tmp_path: Path) -> None:
    """The target's L half outside the frame scores well on what is left of it, but a cut
    outline is not judged: its row and the error say so, not a score below the threshold."""
    ell = family_shape("L", 0.6, 0.3)
    target = _l_target(tmp_path, ell)
    frame = _write(
        tmp_path / "frame.png",
        draw(
            [
                (place(ell, angle_deg=0, size_px=150, centre=(320, 240)), RED),
                (place(ell, angle_deg=0, size_px=150, centre=(620, 240)), BLUE),
            ],
            shade=False,
        ),
    )
    runner = CliRunner()
    result = runner.invoke(cli, ["vision", "match", str(target), str(frame)])
    assert result.exit_code == 0, result.output
    rows = [line for line in result.output.splitlines() if " score " in line]
    (blue,) = [line for line in rows if "rgb(40, 90, 220)" in line]
    (red,) = [line for line in rows if "rgb(210, 40, 40)" in line]
    assert blue.endswith("NOT judgeable (cut by the image border)")
    assert red.startswith("*") and red.endswith("  judgeable")
    cut = _write(
        tmp_path / "cut.png",
        draw([(place(ell, angle_deg=0, size_px=150, centre=(40, 240)), RED)], shade=False),
    )
    result = runner.invoke(cli, ["vision", "match", str(target), str(cut)])
    assert result.exit_code == 1, result.output
    assert "NOT judgeable (cut by the image border)" in result.output
    assert "the best-scoring shape 0 (" in result.output
    assert "is not judgeable: its outline is cut by the image border" in result.output


def test_model_writes_a_glb(tmp_path: Path) -> None:
    scene = load_scene("paper")
    k = Intrinsics.from_hfov()
    poses = {
        "top": CameraPose((10.0, -8.0, 20.0), 0.0, -90.0),
        "front": CameraPose((10.0, -27.0, 3.0), 0.0, 0.0),
        "right": CameraPose((30.0, -8.0, 3.0), 270.0, 0.0),
    }
    paths = [_write(tmp_path / f"{n}.png", render(scene, p, k)) for n, p in poses.items()]
    (tmp_path / "poses.json").write_text(views_to_json({n: (p, k) for n, p in poses.items()}))
    out = tmp_path / "model.glb"
    result = CliRunner().invoke(
        cli,
        [
            "vision",
            "model",
            *map(str, paths),
            "--poses",
            str(tmp_path / "poses.json"),
            "-o",
            str(out),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "watertight True" in result.output
    assert out.read_bytes()[:4] == b"glTF"


def test_bad_input_is_a_one_line_error(tmp_path: Path) -> None:
    bogus = tmp_path / "bogus.png"
    bogus.write_text("not an image")
    result = CliRunner().invoke(cli, ["vision", "vectorize", str(bogus)])
    assert result.exit_code == 2
    assert result.output.strip().count("\n") == 0
    assert "bogus.png: not a decodable image" in result.output


def test_model_from_the_frames_export_writes(tmp_path: Path) -> None:
    """`uavtool export --frames` then `uavtool vision model` of its folder, or of three of its
    photos (their sidecars give the poses), builds the golden flight's target again; a folder
    without the three views, or two photos, is one line and exit 2."""
    golden = Path(__file__).resolve().parents[2] / "recordings" / "golden" / "paper.mcap"
    frames = tmp_path / "frames"
    runner = CliRunner()
    assert runner.invoke(cli, ["export", str(golden), "--frames", str(frames)]).exit_code == 0
    by_folder = runner.invoke(cli, ["vision", "model", str(frames), "-o", str(tmp_path / "a.glb")])
    assert by_folder.exit_code == 0, by_folder.output
    assert "watertight True" in by_folder.output
    tags = {json.loads(p.read_text())["tag"]: p.with_suffix(".png") for p in frames.glob("*.json")}
    photos = [str(tags[name]) for name in ("top", "front", "right")]
    by_photos = runner.invoke(cli, ["vision", "model", *photos, "-o", str(tmp_path / "b.glb")])
    assert by_photos.exit_code == 0, by_photos.output
    assert (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes()
    for args, says in (([str(tmp_path)], "no frame tagged"), (photos[:2], "give three photos")):
        bad = runner.invoke(cli, ["vision", "model", *args, "-o", str(tmp_path / "c.glb")])
        assert bad.exit_code == 2 and "Traceback" not in bad.output
        assert says in bad.output, bad.output
    assert not (tmp_path / "c.glb").exists()


def test_export_takes_the_model_and_the_target_out_of_a_recording(tmp_path: Path) -> None:
    golden = Path(__file__).resolve().parents[2] / "recordings" / "golden" / "paper.mcap"
    model, target = tmp_path / "m.glb", tmp_path / "t.png"
    result = CliRunner().invoke(
        cli, ["export", str(golden), "--model", str(model), "--target", str(target)]
    )
    assert result.exit_code == 0, result.output
    assert model.read_bytes()[:4] == b"glTF" and target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import trimesh

    mesh = trimesh.load(model, force="mesh")
    assert 5.0 < mesh.bounds[1][2] - mesh.bounds[0][2] < 8.0  # red: 6.5 m tall
