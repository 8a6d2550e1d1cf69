"""Mission parameters from `--set` and from files: every value typed and range-checked."""

from __future__ import annotations

import pytest

from uavtool.errors import InputError
from uavtool.mission.params import Params, from_dict, to_dict, valid_keys, with_overrides


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        (
            "vectorize.palette_rgb",
            "5",
            "--set: vectorize.palette_rgb=5: expected a list of lists of 3 integers in [0, 255]",
        ),
        (
            "vectorize.palette_rgb",
            "null",
            "--set: vectorize.palette_rgb=null: expected a list of lists",
        ),
        (
            "mission.move_slack_s",
            "nan",
            "--set: mission.move_slack_s=nan: expected a finite number in [0, 86400]",
        ),
        (
            "mission.link_lost_abort_s",
            "-1",
            "--set: mission.link_lost_abort_s=-1: expected a finite number in (0, 86400]",
        ),
        (
            "mission.retry_wait_s",
            "nan",
            "--set: mission.retry_wait_s=nan: expected a finite number in [0, 86400]",
        ),
        ("mission.max_looks", "0", "--set: mission.max_looks=0: expected an integer in [1, 100]"),
        (
            "recognize.threshold",
            "1.5",
            "--set: recognize.threshold=1.5: expected a finite number in [0, 1]",
        ),
        (
            "viewpoints.oblique_deg",
            "[inf]",
            "--set: viewpoints.oblique_deg=[inf]: expected a list of finite numbers",
        ),
        (
            "mission.assumed_roof_m",
            "45",
            "--set: mission.assumed_roof_m must be below mission.overview_alt_m",
        ),
    ],
)
def test_bad_settings_are_refused_with_the_key(key: str, value: str, message: str) -> None:
    with pytest.raises(InputError) as info:
        with_overrides(Params(), {key: value})
    assert str(info.value).startswith(message)


def test_a_file_is_held_to_the_same_types() -> None:
    data = to_dict(Params())
    data["vectorize"]["palette_rgb"] = 5
    with pytest.raises(InputError, match=r"^p.json: vectorize.palette_rgb=5: expected a list"):
        from_dict(data, source="p.json")
    data["vectorize"]["palette_rgb"] = [[210, 40, 40]]
    assert from_dict(data).vectorize.palette_rgb == ((210, 40, 40),)
    with pytest.raises(InputError, match="expected a mapping"):
        from_dict([], source="p.json")  # type: ignore[arg-type]


def test_defaults_pass_their_own_checks_and_round_trip() -> None:
    assert from_dict(to_dict(Params())) == Params()
    assert len(valid_keys()) > 70
    tuned = with_overrides(Params(), {"mission.move_slack_s": "0", "vectorize.palette_rgb": "[]"})
    assert tuned.mission.move_slack_s == 0.0 and tuned.vectorize.palette_rgb == ()
