"""How many examples a slow fuzz test draws (one whose example flies, replays or rewrites a
recording): all of them in CI (``CI`` set, as GitHub Actions and ``.ci/run`` set it), a third
on a contributor's machine, where the suite runs many times a day. The tests derandomize
their examples: a failure comes back on every run, and ``CI=true pytest PATH::TEST`` draws all
that CI draws."""

from __future__ import annotations

import os


def examples(in_ci: int) -> int:
    return in_ci if os.environ.get("CI") else max(10, in_ci // 3)
