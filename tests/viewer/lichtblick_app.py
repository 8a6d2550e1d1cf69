"""Lichtblick's web app, built from a checkout of its repository, opening a recording in
headless Chromium (`lichtblick_app.cjs`).

The app is published on no registry, so it is built from the checkout ``$UAVTOOL_LICHTBLICK``
names, into a cache folder outside the repository (`lichtblick.cache_folder`), the way its
README builds it: ``yarn install`` and its ``web`` webpack config (development mode: the
production one only adds minification). Three things a plain clone cannot do here are done
around it, changing no code of the app:

- yarn is the release its ``packageManager`` names, from npm's ``@yarnpkg/cli-dist``, run
  directly (the checkout's ``yarnPath`` is a wrapper that wants corepack, which would download
  yarn from outside the package registries); the repository's yarn plugins are left out (none
  is needed to install or build, and a mirror without Git LFS has only pointers to them);
- install scripts are skipped (Electron's would download its binary; the web app needs none);
- fonts that are Git LFS pointers are replaced by the same families from npm (Inter from
  ``inter-ui``, IBM Plex Mono from ``@ibm/plex-mono``): the app waits for its fonts and shows
  nothing if one fails to load.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tests.npm_cache import installing
from tests.viewer.lichtblick import cache_folder, git

DRIVER = Path(__file__).with_name("lichtblick_app.cjs")
_FONTS = "packages/suite-base/src/styles/assets"
_LFS = b"version https://git-lfs"
_FONT_PACKAGES = ("inter-ui@3.19.3", "@ibm/plex-mono@1.1.0")


def has_app(repo: Path) -> bool:
    """Whether ``repo`` holds Lichtblick's web app."""
    return git(repo, "cat-file", "-e", "HEAD:web/webpack.config.ts") is not None


@dataclass(frozen=True)
class LichtblickApp:
    """A built web app (``web``: its ``.webpack`` folder) with its ``node_modules``."""

    web: Path
    node_modules: Path

    def open(self, recording: Path, layout: Path, time: str, out: Path) -> dict[str, Any]:
        """What the app shows of ``recording`` with ``layout``, seeked to ``time``: the Alerts
        (formerly Problems) tab (``badge``, its most severe alert's ``severity`` as the badge's
        colour, ``problems``), each panel's text (``panels``), the box (x, y, width, height) of
        each panel's canvas in the panel's PNG (``canvases``) and console errors; ``out`` gets
        ``page.png`` and a PNG per panel."""
        done = subprocess.run(
            ["node", str(DRIVER), str(self.web), str(self.node_modules), str(recording),
             str(layout), time, str(out)],
            check=False, capture_output=True, text=True, timeout=180,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        seen: dict[str, Any] = json.loads(done.stdout)
        return seen


def build_app(repo: Path) -> LichtblickApp:
    """The web app of ``repo``'s HEAD, built on first use (a few minutes)."""
    folder = cache_folder(repo, "lichtblick-app")
    with installing(folder):
        return _build_app(repo, folder)


def _build_app(repo: Path, folder: Path) -> LichtblickApp:
    app = LichtblickApp(folder / "web" / ".webpack", folder / "node_modules")
    if (app.web / "index.html").is_file():
        return app
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    subprocess.run(["tar", "-x", "-C", str(folder)], input=git(repo, "archive", "HEAD"), check=True)
    rc = folder / ".yarnrc.yml"
    rc.write_text(
        re.sub(r"(?m)^yarnPath:.*\n|^plugins:\n(?:  .*\n)*", "", rc.read_text(encoding="utf-8"))
    )
    tools = folder / ".uavtool"
    tools.mkdir()
    manifest = json.loads((folder / "package.json").read_text(encoding="utf-8"))
    yarn_version = manifest["packageManager"].removeprefix("yarn@")
    for package in (f"@yarnpkg/cli-dist@{yarn_version}", *_FONT_PACKAGES):
        _unpack(package, tools)
    _replace_lfs_fonts(folder / _FONTS, tools)
    env = {
        **os.environ,
        "YARN_IGNORE_PATH": "1",
        "YARN_ENABLE_TELEMETRY": "0",
        "ELECTRON_SKIP_BINARY_DOWNLOAD": "1",
        "PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD": "1",
        "NODE_OPTIONS": "--max-old-space-size=8192",
    }
    yarn = tools / "cli-dist" / "bin" / "yarn.js"
    subprocess.run(
        ["node", str(yarn), "install", "--immutable", "--mode=skip-build"],
        cwd=folder, env=env, check=True, capture_output=True, timeout=1800,
    )  # fmt: skip
    subprocess.run(
        ["node", str(folder / "node_modules" / ".bin" / "webpack"), "--mode", "development",
         "--config", "web/webpack.config.ts"],
        cwd=folder, env=env, check=True, capture_output=True, timeout=1800,
    )  # fmt: skip
    return app


def _unpack(package: str, into: Path) -> None:
    """``npm pack`` ``package`` and unpack it as ``into/<name without scope>``."""
    done = subprocess.run(
        ["npm", "pack", "--json", "--pack-destination", str(into), package],
        check=True, capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    tarball = into / json.loads(done.stdout)[0]["filename"]
    target = into / package.rsplit("@", 1)[0].rsplit("/", maxsplit=1)[-1]
    target.mkdir()
    subprocess.run(
        ["tar", "-x", "-z", "-f", str(tarball), "-C", str(target), "--strip-components=1"],
        check=True,
    )  # fmt: skip


def _replace_lfs_fonts(assets: Path, tools: Path) -> None:
    inter = tools / "inter-ui" / "Inter (web)"
    plex = tools / "plex-mono" / "fonts" / "complete" / "woff2"
    for font in assets.glob("*.woff2"):
        if not font.read_bytes().startswith(_LFS):
            continue
        name = font.stem  # Inter-Medium, PlexMono, PlexMono-Bold, …
        if name.startswith("Inter-"):
            source = inter / font.name
        else:
            style = name.removeprefix("PlexMono").removeprefix("-") or "Regular"
            source = plex / f"IBMPlexMono-{style}.woff2"
        shutil.copy(source, font)
