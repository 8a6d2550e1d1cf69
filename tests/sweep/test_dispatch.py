"""The bounded window: never more than WINDOW tasks on the scheduler, every item's result (or
its error) once, whatever the order they finish in."""

from __future__ import annotations

import time
from typing import Any

from distributed import Client

from uavtool.sweep.dispatch import run_tasks


def _slow_inverse(x: int) -> float:
    time.sleep(0.02 * (x % 3))  # finish out of order
    return 1 / x


class _Counting:
    """A client that counts the tasks submitted through it."""

    def __init__(self, client: Client) -> None:
        self.client = client
        self.submitted = 0

    def submit(self, *args: Any, **kwargs: Any) -> Any:
        self.submitted += 1
        return self.client.submit(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.client, name)


def test_a_bounded_window_gives_every_result_once(scheduler: str) -> None:
    with Client(scheduler) as client:
        counting = _Counting(client)
        seen: dict[int, Any] = {}
        in_flight = []
        for done in run_tasks(counting, _slow_inverse, [(x,) for x in range(12)], window=3):  # type: ignore[arg-type]
            in_flight.append(counting.submitted - len(seen))  # this one included
            assert done.index not in seen
            seen[done.index] = done.error if done.error is not None else done.result
        assert max(in_flight) == 3 and counting.submitted == 12
        assert isinstance(seen.pop(0), ZeroDivisionError)  # a task that raised is reported
        assert seen == {x: 1 / x for x in range(1, 12)}


def test_leaving_early_cancels_what_is_queued(scheduler: str) -> None:
    with Client(scheduler) as client:
        for _ in run_tasks(client, time.sleep, [(0.2,)] * 20, window=4):
            break
        # The client forgets its futures first; the scheduler hears of it a moment later.
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and (
            client.futures or client.run_on_scheduler(_tasks_on_scheduler)
        ):
            time.sleep(0.05)
        assert not client.futures
        assert not client.run_on_scheduler(_tasks_on_scheduler)


def _tasks_on_scheduler(dask_scheduler: Any) -> list[str]:
    return [str(k) for k in dask_scheduler.tasks]
