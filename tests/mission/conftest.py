"""Shared flights: the expensive normal flights run once per session."""

from __future__ import annotations

import dataclasses
from dataclasses import replace

import pytest

from tests.mission import scenes
from tests.mission.driver import Flown, fly
from uavtool.mission import MissionParams, Params
from uavtool.world import Scene, load_scene


@pytest.fixture(scope="session")
def paper() -> Scene:
    return load_scene("paper")


@pytest.fixture(scope="session")
def paper_flight(paper: Scene) -> Flown:
    """The default mission on ``paper``: stops at the first match, builds the model."""
    return fly(paper)


@pytest.fixture(scope="session")
def visit_all_flight(paper: Scene) -> Flown:
    return fly(paper, Params(mission=MissionParams(visit_all=True)))


@pytest.fixture(scope="session")
def turned_flight() -> Flown:
    """``paper`` flown facing east, each look from where the roof fills the photo's height
    (``look_fill`` 1) and a strict threshold (0.95): the red roof's first photo scores below
    it (the walls between its roofs show more from closer), the second (10 m higher)
    matches."""
    params = scenes.with_mission(look_fill=1.0)
    strict = dataclasses.replace(params, recognize=replace(params.recognize, threshold=0.95))
    return fly(scenes.turned(90.0), strict)
