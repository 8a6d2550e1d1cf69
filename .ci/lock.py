"""Merge ``pip freeze`` outputs of several Pythons into one pip constraints file.

    python .ci/lock.py .ci/work/freeze-3.11.txt .ci/work/freeze-3.13.txt > .ci/constraints.txt

Each input is named ``freeze-X.Y.txt``. A package at the same version everywhere is pinned
plainly; one whose version differs by Python (numpy 2.5 needs 3.12) gets one pin per version
with a ``python_version`` marker. Standard library only: it runs before anything is installed.
"""

from __future__ import annotations

import re
import sys
from collections import defaultdict
from pathlib import Path

_PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;]+)")


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def main(paths: list[str]) -> int:
    if not paths:
        print(__doc__, file=sys.stderr)
        return 2
    pins: dict[str, dict[str, str]] = defaultdict(dict)  # package -> python -> version
    names: dict[str, str] = {}
    pythons: list[str] = []
    for path in paths:
        found = re.search(r"freeze-(\d+\.\d+)\.txt$", path)
        if found is None:
            print(f"{path}: expected a file named freeze-X.Y.txt", file=sys.stderr)
            return 2
        python = found.group(1)
        pythons.append(python)
        for line in Path(path).read_text().splitlines():
            pin = _PIN.match(line.strip())
            if pin:
                key = _canonical(pin.group(1))
                names.setdefault(key, pin.group(1))
                pins[key][python] = pin.group(2)
    pythons.sort(key=lambda v: tuple(map(int, v.split("."))))
    print("# The exact versions CI last passed with, on Python " + ", ".join(pythons) + ".")
    print('# pip install -c .ci/constraints.txt -e ".[test]"    (written by .ci/lock.py)')
    for key in sorted(pins):
        by_python = pins[key]
        if len(set(by_python.values())) == 1 and len(by_python) == len(pythons):
            print(f"{names[key]}=={next(iter(by_python.values()))}")
            continue
        for python in pythons:
            if python in by_python:
                print(f'{names[key]}=={by_python[python]}; python_version == "{python}"')
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
