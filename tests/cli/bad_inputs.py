"""A corpus of bad inputs for every command: scene files, images, `--set` and other option
values, and a few recordings. Each builder writes its files under a folder and returns the
command lines that must fail with exit code 2 and one ``uavtool: error:`` line."""

from __future__ import annotations

import json
import struct
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

_BLOCK = (
    "  - name: a\n    color: [200, 30, 30]\n    blocks:\n"
    "      - footprint: {fp}\n        top_m: {top}\n"
)
_SQUARE = "[[0, 0], [4, 0], [4, 3], [0, 3]]"


@dataclass(frozen=True)
class Case:
    kind: str
    name: str
    argv: tuple[str, ...]
    marks: tuple[pytest.MarkDecorator, ...] = field(default=())


def _scene(body: str) -> str:
    return "target: a\nbuildings:\n" + body


def _bomb() -> str:
    lines = ['a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for prev, name in zip("abcdefgh", "bcdefghi", strict=True):
        lines.append(f"{name}: &{name} [" + ",".join([f"*{prev}"] * 9) + "]")
    return "\n".join(lines) + "\n"


BAD_SCENES: dict[str, str] = {
    "alias-bomb.yaml": _bomb(),
    "deep.yaml": "target: a\nbuildings: " + "[" * 50_000 + "]" * 50_000 + "\n",
    "deep.json": '{"target": "a", "buildings": ' + "[" * 50_000 + "]" * 50_000 + "}",
    "deep.toml": 'target = "a"\nbuildings = ' + "[" * 50_000 + "]" * 50_000 + "\n",
    "int-400-digits.yaml": _scene(_BLOCK.format(fp=_SQUARE, top="9" * 400)),
    "int-5000-digits.yaml": _scene(_BLOCK.format(fp=_SQUARE, top="9" * 5000)),
    "int-5000-digits.json": json.dumps({"target": "a", "buildings": []})[:-2] + "9" * 5000 + "]}",
    # Hexadecimal: under the 4096-character limit, past Python's int-to-text limit (4300 digits).
    "hex-4000-digits.yaml": _scene(_BLOCK.format(fp=_SQUARE, top="0x" + "f" * 4000)),
    "hex-4000-digits-color.yaml": _scene(_BLOCK.format(fp=_SQUARE, top=5)).replace(
        "[200, 30, 30]", "[0x" + "f" * 4000 + ", 30, 30]"
    ),
    "hex-4000-digits-footprint.yaml": _scene(
        _BLOCK.format(fp=f"[[0x{'f' * 4000}, 0], [4, 0], [4, 3]]", top=5)
    ),
    "hex-4000-digits.toml": 'target = "a"\n[[buildings]]\nname = "a"\ncolor = [1, 2, 3]\n'
    "[[buildings.blocks]]\nfootprint = [[0, 0], [4, 0], [4, 3]]\ntop_m = 0x" + "f" * 4000 + "\n",
    "duplicate-key.yaml": "target: red\ntarget: blue\nbuildings:\n"
    + _BLOCK.format(fp=_SQUARE, top=5),
    "duplicate-key.json": '{"target": "a", "target": "b", "buildings": []}',
    "recursive-alias.yaml": "target: a\nbuildings: &x [*x]\n",
    "bad-date.yaml": "target: 2001-13-45\nbuildings: []\n",
    "far-away.yaml": _scene(_BLOCK.format(fp="[[0, 0], [1.0e+300, 0], [4, 3]]", top=5)),
    "tall.yaml": _scene(_BLOCK.format(fp=_SQUARE, top="1.0e+30")),
    "nan.yaml": _scene(_BLOCK.format(fp=_SQUARE, top=".nan")),
    "not-utf8.yaml": "\udcff",  # written as a lone 0xff byte
    "empty.yaml": "",
    "list.yaml": "[1, 2, 3]\n",
    "100k-vertices.json": json.dumps(
        {
            "target": "a",
            "buildings": [
                {
                    "name": "a",
                    "color": [1, 2, 3],
                    "blocks": [{"footprint": [[k, k % 2] for k in range(100_000)], "top_m": 5}],
                }
            ],
        }
    ),
    "10k-buildings.json": json.dumps(
        {
            "target": "b0",
            "buildings": [
                {
                    "name": f"b{k}",
                    "color": [1, 2, 3],
                    "blocks": [{"footprint": [[k, 0], [k, 1], [k + 0.5, 0]], "top_m": 1}],
                }
                for k in range(10_000)
            ],
        },
        separators=(",", ":"),
    ),
}


def _png(width: int, height: int, *, idat: bytes = b"") -> bytes:
    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = zlib.crc32(kind + data)
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", idat or zlib.compress(b"\0" * 64))
        + chunk(b"IEND", b"")
    )


def _jpeg_header(width: int, height: int) -> bytes:
    sof = struct.pack(">BBHBHHB", 0xFF, 0xC0, 11, 8, height, width, 1) + b"\x01\x11\x00"
    return b"\xff\xd8" + sof + b"\xff\xd9"


BAD_IMAGES: dict[str, bytes] = {
    "empty.png": b"",
    "huge.png": _png(100_000, 100_000),
    "wide.png": _png(30_000, 2),
    "huge.jpg": _jpeg_header(60_000, 60_000),
    "garbage.png": b"\x89PNG\r\n\x1a\n" + b"\x00" * 100,
    "text.png": b"hello, not an image\n",
}


GOLDEN = Path(__file__).parents[2] / "recordings" / "golden" / "paper.mcap"
ROOT = "{root}"
"""Placeholder for the corpus folder in every command line (the folder is made per test run)."""


def write_files(root: Path) -> None:
    """Write every file the cases name into ``root``."""
    (root / "out").mkdir()
    for name, text in BAD_SCENES.items():
        if name == "not-utf8.yaml":
            (root / name).write_bytes(b"\xff\xfe\x00 garbage")
        else:
            (root / name).write_text(text, encoding="utf-8")
    for name, data in BAD_IMAGES.items():
        (root / name).write_bytes(data)
    (root / "poses.json").write_text("{}")
    golden = GOLDEN.read_bytes()
    for name, data in BAD_RECORDINGS.items():
        (root / name).write_bytes(data)
    (root / "truncated.mcap").write_bytes(golden[: len(golden) // 3])
    (root / "magic-only.mcap").write_bytes(golden[:8])


def cases() -> list[Case]:
    """The whole corpus; paths start with :data:`ROOT`."""
    return [*_scene_cases(), *_image_cases(), *_value_cases(), *_recording_cases()]


def _p(name: str) -> str:
    return f"{ROOT}/{name}"


def _scene_cases() -> list[Case]:
    cases = []
    for name in BAD_SCENES:
        s = _p(name)
        cases += [
            Case("scene", f"scene validate {name}", ("scene", "validate", s)),
            Case(
                "scene",
                f"scene render {name}",
                ("scene", "render", s, "--pos", "0,0,45", "-o", _p("out/r.png")),
            ),
            Case("scene", f"scene show {name}", ("scene", "show", s, "-o", _p("out/s.png"))),
            Case("scene", f"fly --scene {name}", ("fly", "--no-record", "--scene", s)),
            Case("scene", f"sitl --scene {name}", ("sitl", "--scene", s)),
        ]
    return cases


def _image_cases() -> list[Case]:
    cases = []
    g = _p("good.png")
    for name in BAD_IMAGES:
        s = _p(name)
        cases += [
            Case("image", f"fly --target {name}", ("fly", "--no-record", "--target", s)),
            Case("image", f"vision vectorize {name}", ("vision", "vectorize", s)),
            Case("image", f"vision match target {name}", ("vision", "match", s, g)),
            Case("image", f"vision match frame {name}", ("vision", "match", g, s)),
            Case(
                "image",
                f"vision model {name}",
                ("vision", "model", s, g, g, "--poses", _p("poses.json"), "-o", _p("out/m.glb")),
            ),
        ]
    cases.append(Case("image", "vision vectorize missing", ("vision", "vectorize", _p("no.png"))))
    cases.append(Case("image", "vision vectorize a directory", ("vision", "vectorize", _p("out"))))
    cases.append(
        Case("image", "fly --target missing", ("fly", "--no-record", "--target", _p("no.png")))
    )
    return cases


SETTINGS = (
    "vectorize.palette_rgb=5",
    "vectorize.palette_rgb=null",
    "vectorize.palette_rgb=[[1,2]]",
    "vectorize.palette_rgb=[[1,2,300]]",
    "side_vectorize.palette_rgb=[[true,2,3]]",
    "vectorize.denoise_px=4",
    "vectorize.min_saturation=1e3",
    "vectorize.hue_tolerance_deg=inf",
    'viewpoints.oblique_deg=[1,"x"]',
    "viewpoints.oblique_deg=[nan]",
    "viewpoints.distance_step=1",
    "mission.move_slack_s=nan",
    "mission.link_lost_abort_s=-1",
    "mission.retry_wait_s=nan",
    "mission.max_looks=0",
    "mission.max_looks=2.5",
    "mission.max_looks=" + "9" * 5000,
    "mission.look_fill=1e999",
    "mission.overview_alt_m=1e300",
    "mission.assumed_roof_m=60",
    "mission.visit_all=perhaps",
    "recognize.threshold=2",
    "model.max_iterations=0",
    "mission.no_such_key=1",
    "no-equals-sign",
)

FLY_OPTIONS = (
    ("--timeout", "nan"),
    ("--timeout", "-1"),
    ("--timeout", "inf"),
    ("--timeout", "abc"),
    ("--wind", "1e9,0"),
    ("--wind", "nan,0"),
    ("--wind", "5"),
    ("--wind", "-3,0"),
    ("--wind", "5,1e300"),
    ("--link-outage", "10:nan"),
    ("--link-outage", "-5:2"),
    ("--link-outage", "5"),
    ("--speedup", "0"),
    ("--speedup", "nan"),
    ("--speedup", "fast"),
    ("--seed", "-1"),
    ("--seed", "1.5"),
    ("--param", "WPNAV_SPEED=1e39"),
    ("--param", "WPNAV_SPEED=nan"),
    ("--param", "=5"),
    ("--param", "A_NAME_LONGER_THAN_16=1"),
)

SCENE_OPTIONS = (
    ("--pos", "nan,0,45"),
    ("--pos", "0,0"),
    ("--pos", "1e300,0,45"),
    ("--yaw", "inf"),
    ("--pitch", "nan"),
    ("--fov", "0"),
    ("--fov", "nan"),
    ("--noise-seed", "-1"),
    ("--size", "0x0"),
)


def _value_cases() -> list[Case]:
    good_png, out = _p("good.png"), _p("out")
    cases = [Case("value", f"fly --set {s}", ("fly", "--no-record", "--set", s)) for s in SETTINGS]
    cases += [Case("value", f"fly {o} {v}", ("fly", "--no-record", o, v)) for o, v in FLY_OPTIONS]
    render = ("scene", "render", "paper", "-o", f"{out}/r.png")
    for option, value in SCENE_OPTIONS:
        argv = (
            (*render, option, value)
            if option == "--pos"
            else (*render, "--pos", "0,0,45", option, value)
        )
        cases.append(Case("value", f"scene render {option} {value}", argv))
    rand = ("scene", "random", "-o", f"{out}/r.yaml")
    cases += [
        Case("value", "scene random --seed -1", (*rand, "--seed", "-1")),
        Case("value", "scene random --margin nan", (*rand, "--seed", "1", "--margin", "nan")),
        Case("value", "scene random --buildings 0", (*rand, "--seed", "1", "--buildings", "0")),
        Case(
            "value",
            "scene random --buildings 10000",
            (*rand, "--seed", "1", "--buildings", "10000"),
        ),
        Case(
            "value",
            "scene random --hard --spread inf",
            (*rand, "--seed", "1", "--hard", "--spread", "inf"),
        ),
        Case(
            "value",
            "vision vectorize --epsilon nan",
            ("vision", "vectorize", good_png, "--epsilon", "nan"),
        ),
        Case(
            "value",
            "vision vectorize --spacing 0",
            ("vision", "vectorize", good_png, "--spacing", "0"),
        ),
        Case(
            "value",
            "vision match --threshold 2",
            ("vision", "match", good_png, good_png, "--threshold", "2"),
        ),
        Case(
            "value",
            "vision vectorize -o in missing dir",
            ("vision", "vectorize", good_png, "-o", f"{out}/no/s.json"),
        ),
        Case(
            "value",
            "vision vectorize --overlay bad extension",
            ("vision", "vectorize", good_png, "--overlay", f"{out}/o.xyz"),
        ),
    ]
    cases += [
        Case("value", f"replay --set {s}", ("replay", str(GOLDEN), "--set", s))
        for s in SETTINGS[:4] + SETTINGS[11:14]
    ]
    return cases


BAD_RECORDINGS: dict[str, bytes] = {
    "not-an-mcap.mcap": b"hello, this is not an MCAP file at all\n",
    "empty.mcap": b"",
}


def _recording_cases() -> list[Case]:
    commands: dict[str, Callable[[str], tuple[str, ...]]] = {
        "info": lambda p: ("info", p),
        "replay": lambda p: ("replay", p),
        "replay --check": lambda p: ("replay", "--check", p),
        "export": lambda p: ("export", p, "--tlog", _p("out/o.tlog")),
        "view": lambda p: ("view", p, "--save", _p("out/o.rrd")),
    }
    files = {**{n: _p(n) for n in BAD_RECORDINGS}, "missing.mcap": _p("missing.mcap")}
    cases = []
    for name, path in files.items():
        for label, argv in commands.items():
            cases.append(Case("recording", f"{label} {name}", argv(path)))
    for label, argv in commands.items():
        cases.append(Case("recording", f"{label} a directory", argv(_p("out"))))
    # A truncated file is recovered by design (info, replay, export and view read what it
    # holds); only --check, which needs a whole file, refuses it.
    cases += [
        Case("recording", f"replay --check {name}", ("replay", "--check", _p(name)))
        for name in ("truncated.mcap", "magic-only.mcap")
    ]
    cases.append(
        Case("recording", "import empty", ("import", _p("empty.mcap"), "-o", _p("out/i.mcap")))
    )
    return cases
