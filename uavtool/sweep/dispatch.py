"""Many tasks on a Dask client through a bounded window: a few tasks per worker thread are on
the scheduler at any time, and one more is submitted as each finishes. A 100,000-flight sweep
so never holds 100,000 tasks (their arguments, keys and futures) on the scheduler or in the
driver at once, and the first results come back as soon as with everything submitted.

Results are yielded as they finish, with the index of their item: callers that need an order
sort by it, so nothing depends on the order tasks finish in.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from distributed import Client, Future

PER_THREAD = 4
"""Tasks in flight per worker thread: enough that no worker waits for the driver between two
tasks, few enough that the scheduler's memory does not grow with the sweep."""
MIN_WINDOW = 8
_REFRESH_S = 10.0  # how often the window follows workers joining or leaving


@dataclass(frozen=True, slots=True)
class Done:
    """One finished task: its item's index and its result, or the exception that ended it
    (out of retries, or its worker died too often)."""

    index: int
    result: Any = None
    error: BaseException | None = None


def run_tasks(
    client: Client,
    fn: Callable[..., Any],
    items: Sequence[tuple[Any, ...]],
    *,
    kwargs: dict[str, Any] | None = None,
    keys: Sequence[str] | None = None,
    retries: int = 0,
    window: int | None = None,
) -> Iterator[Done]:
    """Run ``fn(*items[i], **kwargs)`` for every ``i``, at most ``window`` at a time (default:
    :data:`PER_THREAD` per worker thread, at least :data:`MIN_WINDOW`); yield each as it
    finishes. ``keys`` names the tasks on the scheduler. Leaving the loop early (Ctrl-C, a
    ``break``) cancels whatever is still queued or running."""
    from distributed import as_completed  # noqa: PLC0415

    sizer = _Window(client, window)
    pending: dict[Future[Any], int] = {}
    queue = iter(range(len(items)))

    def submit(i: int) -> Future[Any]:
        future = client.submit(
            fn,
            *items[i],
            **(kwargs or {}),
            key=keys[i] if keys is not None else None,
            pure=False,
            retries=retries,
        )
        pending[future] = i
        return future

    started = [submit(i) for _, i in zip(range(sizer.size()), queue, strict=False)]
    finished = as_completed(started)
    try:
        for future in finished:
            i = pending.pop(future)
            try:
                done = Done(i, result=future.result())
            except Exception as exc:  # a task that raised: the caller makes it a row
                done = Done(i, error=exc)
            yield done
            room = sizer.size() - len(pending)
            for _, j in zip(range(max(room, 0)), queue, strict=False):
                finished.add(submit(j))
    finally:
        if pending:
            client.cancel(list(pending))


class _Window:
    """How many tasks may be in flight: fixed, or a few per worker thread right now."""

    def __init__(self, client: Client, fixed: int | None) -> None:
        self._client = client
        self._fixed = fixed
        self._size = 0
        self._at = -float("inf")

    def size(self) -> int:
        if self._fixed is not None:
            return max(self._fixed, 1)
        now = time.monotonic()
        if now - self._at >= _REFRESH_S:
            threads = sum(self._client.nthreads().values())
            self._size = max(PER_THREAD * threads, MIN_WINDOW)
            self._at = now
        return self._size
