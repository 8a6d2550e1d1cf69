"""Keeping a fleet's vehicles apart: each vehicle flies only inside airspace it has claimed, and
a claim is granted only when it lies at least the separation from every other vehicle's.

Claims are simple solids in the fleet's frame (ENU metres around the first vehicle's home): a
**point** (hovering, or standing on the ground), a **lane** (a horizontal segment flown at one
altitude) and a **column** (a vertical cylinder between two altitudes: a take-off, a landing,
a look down from lower). Every vehicle always holds exactly one claim, which covers where it
is; it asks for the next before it moves, waits where it is while the answer is no, and shrinks
its claim to a point when it arrives. Each claim is widened by how far a vehicle may stray from
where it was sent (``margin_m``), so two granted claims keep the vehicles themselves apart.

Two claims are apart when their vertical gap or their horizontal gap is at least the
separation: a sufficient test (the distance between them is at least the larger of the two),
never a guess.
"""

from __future__ import annotations

from dataclasses import dataclass

from uavtool.nav.geometry import point_segment_distance, segments_intersect

EN = tuple[float, float]


@dataclass(frozen=True, slots=True)
class Claim:
    """Airspace one vehicle may fly in: the horizontal segment ``a``–``b`` (a point when they
    are equal) swept sideways by ``radius_m``, between altitudes ``low_m`` and ``high_m``."""

    a: EN
    b: EN
    radius_m: float
    low_m: float
    high_m: float
    what: str = ""
    parked: bool = False
    """A vehicle standing on the ground, motors off: it strays nowhere (no margin)."""

    @staticmethod
    def point(at: EN, alt_m: float, what: str = "") -> Claim:
        return Claim(at, at, 0.0, alt_m, alt_m, what)

    @staticmethod
    def parked_at(at: EN, what: str = "on the ground") -> Claim:
        return Claim(at, at, 0.0, 0.0, 0.0, what, parked=True)

    @staticmethod
    def lane(a: EN, b: EN, alt_m: float, what: str = "") -> Claim:
        return Claim(a, b, 0.0, alt_m, alt_m, what)

    @staticmethod
    def column(at: EN, radius_m: float, low_m: float, high_m: float, what: str = "") -> Claim:
        return Claim(at, at, radius_m, min(low_m, high_m), max(low_m, high_m), what)

    def covers(self, at: EN, alt_m: float, tolerance_m: float) -> bool:
        """Whether a vehicle at ``at``/``alt_m`` is inside (within ``tolerance_m``)."""
        inside_up = self.low_m - tolerance_m <= alt_m <= self.high_m + tolerance_m
        near = point_segment_distance(at, self.a, self.b) <= self.radius_m + tolerance_m
        return inside_up and near


def gap_m(p: Claim, q: Claim) -> float:
    """A lower bound of the distance between two claims: the larger of their vertical and
    horizontal gaps."""
    vertical = max(q.low_m - p.high_m, p.low_m - q.high_m, 0.0)
    horizontal = max(_segment_segment(p.a, p.b, q.a, q.b) - p.radius_m - q.radius_m, 0.0)
    return max(vertical, horizontal)


class Airspace:
    """The claims of ``vehicles`` vehicles kept ``separation_m`` apart, each widened by
    ``margin_m`` (how far a vehicle may stray from where it was sent; a parked vehicle strays
    nowhere). Vehicle ``i`` starts parked at ``starts[i]`` (its home)."""

    def __init__(self, starts: tuple[EN, ...], *, separation_m: float, margin_m: float) -> None:
        if not (separation_m > 0.0 and margin_m >= 0.0):
            raise ValueError("separation must be > 0 and the margin ≥ 0")
        self.separation_m = separation_m
        self.margin_m = margin_m
        self.held: list[Claim] = [Claim.parked_at(at, "home") for at in starts]
        self.refusals = 0
        """How many requests were refused (each one a wait of one telemetry period)."""
        self.wanted: dict[int, Claim] = {}
        """Vehicle → the claim it was last refused and still waits for."""

    def blocker(self, vehicle: int, claim: Claim) -> int | None:
        """The first other vehicle whose claim is nearer ``claim`` than the separation (with
        the margins of both), or None."""
        for other, held in enumerate(self.held):
            if other != vehicle and gap_m(claim, held) < self.needed_m(claim, held):
                return other
        return None

    def needed_m(self, p: Claim, q: Claim) -> float:
        """The gap two claims need: the separation and each one's margin."""
        return self.separation_m + sum(0.0 if c.parked else self.margin_m for c in (p, q))

    def request(self, vehicle: int, claim: Claim) -> bool:
        """Grant ``claim`` to ``vehicle`` (it replaces what it held) if it is apart from every
        other vehicle's; False, and nothing changes, if not."""
        if self.blocker(vehicle, claim) is not None:
            self.refusals += 1
            self.wanted[vehicle] = claim
            return False
        self.held[vehicle] = claim
        self.wanted.pop(vehicle, None)
        return True

    def waits_for(self, vehicle: int, other: int) -> bool:
        """Whether ``vehicle`` waits for a claim that ``other``'s holds up."""
        wanted, held = self.wanted.get(vehicle), self.held[other]
        return wanted is not None and gap_m(wanted, held) < self.needed_m(wanted, held)

    def holding_up(self, vehicle: int) -> int | None:
        """The first other vehicle waiting for a claim that ``vehicle``'s holds up, or None
        (a vehicle that only waits may give way)."""
        return next((o for o in sorted(self.wanted) if self.waits_for(o, vehicle)), None)

    def shrink(self, vehicle: int, at: EN, alt_m: float, what: str = "") -> None:
        """The vehicle arrived: it holds only the point where it is (always granted: the point
        lies inside what it held)."""
        self.held[vehicle] = Claim.point(at, alt_m, what)

    def narrow(self, vehicle: int, claim: Claim) -> None:
        """The vehicle now needs only ``claim``, which lies inside what it held (always
        granted: it takes nothing from anyone)."""
        self.held[vehicle] = claim

    def park(self, vehicle: int, at: EN) -> None:
        """The vehicle landed and disarmed: it holds only where it stands."""
        self.held[vehicle] = Claim.parked_at(at)
        self.wanted.pop(vehicle, None)


def _segment_segment(a: EN, b: EN, c: EN, d: EN) -> float:
    """Least distance between the segments ``a``–``b`` and ``c``–``d`` in the plane."""
    if segments_intersect(a, b, c, d):
        return 0.0
    return min(
        point_segment_distance(a, c, d),
        point_segment_distance(b, c, d),
        point_segment_distance(c, a, b),
        point_segment_distance(d, a, b),
    )
