"""Commands that write: never over their input, nothing left behind when they fail, a full
disk or a named pipe is one line."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.recording.sample import write_sample
from uavtool.cli import cli
from uavtool.recording import RecordingWriter
from uavtool.recording.files import SameFileError, atomic_output

GOLDEN = Path(__file__).resolve().parents[2] / "recordings" / "golden" / "paper.mcap"


def _run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, list(args))
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.stdout, result.stderr


def _same(path: Path, how: str) -> Path:
    """A name for ``path`` itself: the path, a symbolic link or a hard link to it."""
    if how == "path":
        return path
    other = path.with_name(f"{how}.mcap")
    if how == "symlink":
        other.symlink_to(path.name)
    else:
        os.link(path, other)
    return other


# command line writing ``{out}`` from the recording ``{rec}``
_WRITERS = {
    "export": ["export", "{rec}", "--tlog", "{out}"],
    "view": ["view", "{rec}", "--save", "{out}"],
    "replay": ["replay", "-q", "{rec}", "--output", "{out}"],
    "recover": ["info", "--recover", "{rec}", "-o", "{out}"],
    "refly": ["replay", "--refly", "{rec}", "--output", "{out}"],
}


@pytest.mark.parametrize("how", ["path", "symlink", "hardlink"])
@pytest.mark.parametrize("command", sorted(_WRITERS))
def test_output_over_input_is_refused_and_the_input_intact(
    tmp_path: Path, command: str, how: str
) -> None:
    rec = tmp_path / "rec.mcap"
    shutil.copy(GOLDEN, rec)
    before = rec.read_bytes()
    out = _same(rec, how)
    args = [a.format(rec=rec, out=out) for a in _WRITERS[command]]
    code, _, err = _run(*args)
    assert code == 2
    assert err.count("\n") == 1 and "writing it would destroy it" in err, err
    assert rec.read_bytes() == before
    assert out.resolve() == rec.resolve() or out.samefile(rec)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted({"rec.mcap", out.name})


def test_import_over_its_tlog_is_refused(tmp_path: Path) -> None:
    rec, tlog = tmp_path / "rec.mcap", tmp_path / "rec.tlog"
    write_sample(rec)
    assert _run("export", str(rec), "--tlog", str(tlog))[0] == 0
    before = tlog.read_bytes()
    code, _, err = _run("import", str(tlog), "-o", str(tlog))
    assert code == 2 and "writing it would destroy it" in err
    assert tlog.read_bytes() == before


@pytest.mark.parametrize(
    ("args", "content"),
    [
        (["export", "{bad}", "--tlog", "{tmp}/out.tlog"], b"\x89MCAP0\r\n"),
        (["export", "{bad}", "--tlog", "{tmp}/out.tlog"], b"not mcap"),
        (["view", "{bad}", "--save", "{tmp}/out.rrd"], b"not mcap"),
        (["view", "{bad}", "--save", "{tmp}/out.rrd"], None),  # a recording without a mission
        (["replay", "{bad}", "--output", "{tmp}/out.mcap"], None),
        (["info", "--recover", "{bad}", "-o", "{tmp}/out.mcap"], b""),
        (["import", "{bad}", "-o", "{tmp}/out.mcap"], b"\x00" * 100),
    ],
)
def test_no_file_is_left_after_a_failing_command(
    tmp_path: Path, args: list[str], content: bytes | None
) -> None:
    bad = tmp_path / "bad.mcap"
    if content is None:  # a whole recording, of no mission
        with RecordingWriter(bad, fsync=False) as writer:
            writer.add_json_topic("/notes", schema_name="note", schema={"type": "object"})
            writer.write_json("/notes", {"text": "hi"}, log_time_ns=1)
    else:
        bad.write_bytes(content)
    code, _, err = _run(*[a.format(bad=bad, tmp=tmp_path) for a in args])
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert [p.name for p in tmp_path.iterdir()] == ["bad.mcap"]


def test_a_full_disk_is_one_line(tmp_path: Path) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full")
    rec = tmp_path / "rec.mcap"
    write_sample(rec)
    code, _, err = _run("export", str(rec), "--tlog", "/dev/full")
    assert code == 2
    assert err == "uavtool: error: /dev/full: cannot write: No space left on device\n"
    assert Path("/dev/full").is_char_device()  # written in place, never renamed over


@pytest.mark.parametrize(
    "args",
    [
        ["info", "{fifo}"],
        ["export", "{fifo}", "--tlog", "{tmp}/x.tlog"],
        ["import", "{fifo}", "-o", "{tmp}/x.mcap"],
        ["replay", "--check", "{fifo}"],
        ["view", "{fifo}", "--save", "{tmp}/x.rrd"],
    ],
)
def test_a_named_pipe_is_refused_at_once(tmp_path: Path, args: list[str]) -> None:
    fifo = tmp_path / "pipe.mcap"
    os.mkfifo(fifo)
    t0 = time.monotonic()
    code, _, err = _run(*[a.format(fifo=fifo, tmp=tmp_path) for a in args])
    assert time.monotonic() - t0 < 5.0
    assert code == 2
    assert err == f"uavtool: error: {fifo}: a named pipe, not a recording file\n"
    assert [p.name for p in tmp_path.iterdir()] == ["pipe.mcap"]


def _write(path: Path, text: str) -> None:
    path.write_text(text)


@pytest.mark.parametrize("fail", [None, RuntimeError("boom")])
def test_atomic_output_renames_on_success_only(tmp_path: Path, fail: Exception | None) -> None:
    out = tmp_path / "out.txt"
    out.write_text("old")
    write: Callable[[Path, str], None] = _write

    def run() -> None:
        with atomic_output(out) as tmp:
            assert tmp.parent == out.parent and tmp != out
            write(tmp, "new")
            assert out.read_text() == "old"  # untouched until complete
            if fail is not None:
                raise fail

    if fail is None:
        run()
        assert out.read_text() == "new"
    else:
        with pytest.raises(RuntimeError):
            run()
        assert out.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_atomic_output_through_a_symlink_keeps_the_link(tmp_path: Path) -> None:
    target, link = tmp_path / "target.txt", tmp_path / "link.txt"
    target.write_text("old")
    link.symlink_to(target.name)
    with atomic_output(link) as tmp:
        tmp.write_text("new")
    assert link.is_symlink() and target.read_text() == "new"
    with pytest.raises(SameFileError), atomic_output(link, inputs=[target]):
        pass


def test_info_recover_onto_a_full_disk_is_one_line(tmp_path: Path) -> None:
    if not Path("/dev/full").exists():
        pytest.skip("no /dev/full")
    rec = tmp_path / "rec.mcap"
    write_sample(rec)
    code, _, err = _run("info", "--recover", str(rec), "-o", "/dev/full")
    assert code == 2
    assert err == "uavtool: error: /dev/full: cannot write: No space left on device\n"


@pytest.mark.parametrize(
    "args",
    [
        ["scene", "show", "paper", "-o", "{fifo}.png"],
        ["scene", "target", "paper", "-o", "{fifo}.png"],
        ["scene", "render", "paper", "--pos", "0,0,45", "-o", "{fifo}.png"],
        ["scene", "random", "--seed", "1", "-o", "{fifo}.yaml"],
        ["info", "--recover", "{rec}", "-o", "{fifo}.mcap"],
        ["export", "{rec}", "--tlog", "{fifo}.tlog"],
        ["view", "{rec}", "--save", "{fifo}.rrd"],
        ["vision", "vectorize", "{png}", "--overlay", "{fifo}.png"],
    ],
)
def test_an_output_pipe_nobody_reads_is_refused_at_once(tmp_path: Path, args: list[str]) -> None:
    # Opening a pipe for writing waits for a reader: these hung for ever. Run in a process of
    # its own, so that a hang fails the test instead of stopping the suite.
    rec, png = tmp_path / "rec.mcap", tmp_path / "frame.png"
    write_sample(rec)
    assert _run("scene", "show", "paper", "-o", str(png))[0] == 0
    fifo = tmp_path / "out"
    argv = [a.format(fifo=fifo, rec=rec, png=png) for a in args]
    os.mkfifo(argv[-1])
    done = subprocess.run(
        [sys.executable, "-m", "uavtool", *argv],
        check=False,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr == (
        f"uavtool: error: {argv[-1]}: a named pipe that nobody reads (writing would wait for"
        " ever): start its reader first, or write to a file\n"
    )


def test_an_output_pipe_with_a_reader_gets_the_whole_file(tmp_path: Path) -> None:
    fifo, got = tmp_path / "out.png", tmp_path / "got.png"
    os.mkfifo(fifo)
    with got.open("wb") as sink, subprocess.Popen(["cat", str(fifo)], stdout=sink) as reader:
        time.sleep(0.2)  # let it open its end
        assert _run("scene", "show", "paper", "-o", str(fifo))[0] == 0
        assert reader.wait(timeout=10) == 0
    assert _run("scene", "show", "paper", "-o", str(tmp_path / "file.png"))[0] == 0
    assert got.read_bytes() == (tmp_path / "file.png").read_bytes()


def test_the_rename_is_put_on_disk_with_its_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """After the rename from ``.partial``, the folder itself is synced: a power cut then cannot
    bring back the partial name (or no name at all) for a file reported whole."""
    synced: list[str] = []
    real_fsync = os.fsync

    def fsync(fd: int) -> None:
        synced.append(str(Path(f"/proc/self/fd/{fd}").readlink()))
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    out = tmp_path / "out.bin"
    with atomic_output(out) as tmp:
        tmp.write_bytes(b"whole")
        assert not synced
    assert out.read_bytes() == b"whole"
    assert synced == [str(tmp_path)]
