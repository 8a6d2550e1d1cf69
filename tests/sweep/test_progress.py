"""The progress line: counts, rate and ETA from the flights finished in this run."""

from __future__ import annotations

from uavtool.sweep.progress import Progress, format_progress


def test_eta_comes_from_the_flights_flown_in_this_run() -> None:
    # 10 resumed, 5 flown in 30 s: 5 left at 6 s each.
    p = Progress(done=5, total=20, skipped=10, errors=1, elapsed_s=30.0)
    assert p.eta_s == 30.0
    line = format_progress(p, width=10)
    assert line.startswith("[########..] 15/20 flights, 10 resumed, 1 error, 10.0/min, ETA 30s")


def test_no_eta_before_the_first_flight_ends() -> None:
    assert format_progress(Progress(0, 4), width=4) == "[....] 0/4 flights, ETA --"
