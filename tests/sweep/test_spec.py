"""Sweep specs: what a spec expands to, and bad specs named by their key path (exit 2)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from uavtool.cli import cli
from uavtool.sweep import SpecError, load_spec, plan_flights
from uavtool.sweep.plan import dimension_keys


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(text)
    return path


def test_scenes_grid_and_draws_multiply(tmp_path: Path) -> None:
    spec = load_spec(
        write(
            tmp_path,
            """
            [scenes]
            builtin = ["paper", "arch"]
            hard = { seeds = { first = 5, count = 3 }, max_buildings = 6 }
            [grid]
            seed = [0, 1]
            "set.recognize.threshold" = { from = 0.7, to = 0.8, step = 0.05 }
            [random]
            draws = 2
            wind_speed_ms = { uniform = [0, 8] }
            param.WPNAV_SPEED = { choice = [500, 800] }
            """,
        )
    )
    flights = plan_flights(spec)
    assert len(flights) == (2 + 3) * (2 * 3) * 2
    assert [f.index for f in flights] == list(range(len(flights)))
    assert flights[0].label == "paper" and flights[-1].label == "hard:7"
    assert flights[0].settings() == {"recognize.threshold": "0.7"}
    assert flights[0].vehicle_params()[0][0] == "WPNAV_SPEED"
    assert "set.recognize.threshold" in dimension_keys(spec)
    # Draws depend on the spec alone, and on each flight's own place in it: the same again,
    # and a scene added before leaves the other scenes' draws as they were.
    assert [f.inputs for f in plan_flights(spec)] == [f.inputs for f in flights]
    more = plan_flights(load_spec(tmp_path / "spec.toml", ['scenes.builtin=["dense", "paper"]']))
    for label in ("paper", "hard:5"):
        assert [(f.inputs, f.key) for f in more if f.label == label] == [
            (f.inputs, f.key) for f in flights if f.label == label
        ]


def test_cases_go_together_and_cross_the_scenes_and_the_grid(tmp_path: Path) -> None:
    spec = load_spec(
        write(
            tmp_path,
            """
            [scenes]
            builtin = ["paper", "arch"]
            [grid]
            noise = [false, true]
            [[cases]]
            seed = 11
            wind_speed_ms = 6
            [[cases]]
            seed = 21
            set.mission.max_looks = 1
            """,
        )
    )
    flights = plan_flights(spec)
    assert [(f.label, f.value("seed"), f.value("noise")) for f in flights] == [
        (scene, seed, noise)
        for scene in ("paper", "arch")
        for seed in (11, 21)
        for noise in (False, True)
    ]
    assert [f.value("wind_speed_ms") for f in flights[:4]] == [6.0, 6.0, 0.0, 0.0]
    assert [f.settings() for f in flights[1:3]] == [{}, {"mission.max_looks": "1"}]
    assert dimension_keys(spec)[-1] == "set.mission.max_looks"


def test_a_changed_input_is_a_new_flight_key(tmp_path: Path) -> None:
    a = plan_flights(load_spec(write(tmp_path, "[grid]\nseed = [1]\n")))[0]
    b = plan_flights(load_spec(write(tmp_path, "[grid]\nseed = [2]\n")))[0]
    assert a.stem.startswith("000000-paper-") and a.key != b.key


@pytest.mark.parametrize(
    ("text", "overrides", "where"),
    [
        ('[grid]\nwind_speed_ms = [0, "fast"]\n', [], "grid.wind_speed_ms[1]: expected a number"),
        ('[grid]\n"set.recognize.treshold" = [0.7]\n', [], "grid.set.recognize.treshold: "),
        ("[grid]\nset.recognize.threshold = [2]\n", [], "grid.set.recognize.threshold[0]"),
        ("[grid]\nparam.NOPE = [1]\n", [], "grid.param.NOPE: the built-in vehicle has no"),
        ("[grid]\naltitude = [1]\n", [], "grid.altitude: unknown flight input"),
        ('[scenes]\nbuiltin = ["nowhere"]\n', [], "scenes.builtin[0]: no built-in scene"),
        ('[scenes]\nfiles = ["missing.yaml"]\n', [], "scenes.files[0]: "),
        (
            "[scenes.hard]\nseeds = [1]\nmirror_decoy_p = 2.0\n",
            [],
            "scenes.hard[0]: mirror_decoy_p",
        ),
        ("[scenes.hard]\nseeds = [1]\ncolour = 2\n", [], "scenes.hard[0].colour: unknown key"),
        ("[random]\nwind_from_deg = { gaussian = [0, 1] }\n", [], "random.wind_from_deg: expected"),
        ("[random]\nseed = { uniform = [0, 9] }\n", [], "random.seed: drew"),
        ('[sweep]\nformat = "xlsx"\n', [], "sweep.format: expected 'parquet' or 'csv'"),
        ("[grid\nseed = 1\n", [], "not valid TOML"),
        ("", ["grid.seed=[-1]"], "grid.seed[0]: expected a whole number in [0, "),
        # seeds beyond a 64-bit column: the attack run's 4,300 digits passed the spec before
        (f"[grid]\nseed = [1, {'9' * 4300}]\n", [], "grid.seed[1]: expected a whole number in"),
        ("[grid]\nseed = [9223372036854775808]\n", [], "grid.seed[0]: expected a whole number"),
        (f"[[cases]]\nseed = {'9' * 4300}\n", [], "cases[0].seed: expected a whole number in"),
        (f"[random]\nrng_seed = {'9' * 4300}\n", [], "random.rng_seed: expected a whole number"),
        (f"[scenes.hard]\nseeds = [{'9' * 4300}]\n", [], "scenes.hard[0].seeds[0]: expected"),
        ("[scenes.random]\nseeds = [-3]\n", [], "scenes.random[0].seeds[0]: expected a whole"),
        ("[grid]\nseed = [1]\n[random]\nseed = 3\n", [], "random.seed: already a grid dimension"),
        ("[[cases]]\nseed = 1\n[[cases]]\nwind = 3\n", [], "cases[1].wind: unknown flight input"),
        ("[[cases]]\nnoise = 1\n", [], "cases[0].noise: expected true or false"),
        ("[grid]\nseed = [1]\n[[cases]]\nseed = 3\n", [], "cases[0].seed: already a grid"),
        ("cases = 3\n", [], "cases: expected an array of tables"),
        ("[sweep]\ntimeout_s = 0\n", [], "sweep.timeout_s: expected vehicle seconds > 0"),
    ],
)
def test_a_bad_spec_exits_2_naming_the_key_path(
    tmp_path: Path, text: str, overrides: list[str], where: str
) -> None:
    path = write(tmp_path, text)
    args = ["sweep", str(path), "--output", str(tmp_path / "out")]
    for o in overrides:
        args += ["--set", o]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 2, result.output
    assert f"{path}: {where}" in result.output or where in result.output
    assert "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1 and len(result.output) < 700
    assert not (tmp_path / "out").exists()


def test_spec_error_carries_the_key_path(tmp_path: Path) -> None:
    with pytest.raises(SpecError) as info:
        load_spec(write(tmp_path, "[grid]\nnoise = [1]\n"))
    assert info.value.key_path == "grid.noise[0]"
    assert info.value.exit_code == 2
