"""The fleet's airspace: claims are granted only where they keep the separation (with each
one's margin), and a vehicle always holds exactly one claim."""

from __future__ import annotations

import pytest

from uavtool.mission.airspace import Airspace, Claim, gap_m


def test_the_gap_is_the_larger_of_the_vertical_and_horizontal_gaps() -> None:
    low = Claim.lane((0.0, 0.0), (100.0, 0.0), 20.0)
    high = Claim.lane((0.0, 0.0), (100.0, 0.0), 30.0)
    assert gap_m(low, high) == pytest.approx(10.0)  # one above the other
    aside = Claim.lane((0.0, 7.0), (100.0, 7.0), 20.0)
    assert gap_m(low, aside) == pytest.approx(7.0)  # side by side
    crossing = Claim.lane((50.0, -50.0), (50.0, 50.0), 20.0)
    assert gap_m(low, crossing) == 0.0  # the ways cross at one altitude
    column = Claim.column((50.0, 10.0), 2.0, 0.0, 40.0)
    assert gap_m(low, column) == pytest.approx(8.0)  # 10 m off the way, 2 m of radius
    assert gap_m(column, Claim.point((50.0, 10.0), 45.0)) == pytest.approx(5.0)  # above it


def test_a_claim_is_granted_only_apart_from_every_other() -> None:
    space = Airspace(((0.0, 0.0), (8.0, 0.0)), separation_m=5.0, margin_m=1.5)
    # Each starts parked at home: parked vehicles keep no margin.
    assert space.held[0].parked and space.held[1].parked
    up = Claim.column((0.0, 0.0), 0.6, 0.0, 30.0)
    assert space.request(0, up)  # 8 - 0.6 m from the other, parked: 5 + 1.5 needed
    also_up = Claim.column((8.0, 0.0), 0.6, 0.0, 30.0)
    assert not space.request(1, also_up)  # two columns 6.8 m apart need 5 + 2 x 1.5 m
    assert space.blocker(1, also_up) == 0 and space.refusals == 1
    assert space.held[1].parked  # refused: it holds what it held
    space.shrink(0, (0.0, 0.0), 30.0)  # arrived at 30 m: only that point is held
    assert not space.request(1, also_up)  # its column still reaches 30 m beside it
    lower = Claim.column((8.0, 0.0), 0.6, 0.0, 21.0)
    assert space.request(1, lower)  # 9 m under it: apart


def test_a_vehicle_knows_whom_it_holds_up_until_the_way_is_granted() -> None:
    space = Airspace(((0.0, 0.0), (30.0, 0.0)), separation_m=5.0, margin_m=1.5)
    assert space.request(0, Claim.point((0.0, 0.0), 40.0))  # waiting, hovering
    down = Claim.column((3.0, 0.0), 0.6, 20.0, 60.0)  # the other's way down past it
    assert not space.request(1, down)
    assert space.holding_up(0) == 1 and space.holding_up(1) is None
    assert space.wanted == {1: down}
    assert space.request(0, Claim.point((0.0, 30.0), 40.0))  # it gave way
    assert space.holding_up(0) is None  # the refused claim, asked again, is granted next
    assert space.request(1, down) and space.wanted == {}
    # A vehicle that lands is waiting for nothing any more.
    assert not space.request(0, Claim.column((3.0, 3.0), 0.6, 0.0, 60.0))
    space.park(0, (0.0, 30.0))
    assert space.wanted == {}


def test_a_parked_vehicle_holds_only_where_it_stands() -> None:
    space = Airspace(((0.0, 0.0), (10.0, 0.0)), separation_m=5.0, margin_m=1.5)
    assert space.request(0, Claim.lane((0.0, 0.0), (0.0, 50.0), 20.0))
    space.park(0, (3.0, 4.0))
    assert space.held[0] == Claim.parked_at((3.0, 4.0))
    # A lane 7 m over where it landed: 5 m and one margin are enough.
    assert space.request(1, Claim.lane((3.0, -50.0), (3.0, 50.0), 7.0))


def test_covers_says_whether_a_position_is_inside() -> None:
    c = Claim((0.0, 0.0), (10.0, 0.0), 1.0, 5.0, 20.0)
    assert c.covers((5.0, 0.9), 10.0, 0.0)
    assert not c.covers((5.0, 1.2), 10.0, 0.0)
    assert not c.covers((5.0, 0.0), 21.0, 0.0)
    assert c.covers((5.0, 0.0), 21.0, 1.5)


def test_nonsense_is_refused() -> None:
    with pytest.raises(ValueError, match="separation"):
        Airspace(((0.0, 0.0),), separation_m=0.0, margin_m=1.0)
