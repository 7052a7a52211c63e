"""The bad-input corpus (cases.toml + specs/): every command line runs in-process under a time
bound and must exit with the expected status and a message holding the expected fragment,
with no traceback, no numpy warning, no file left behind and no change to any file but its
declared outputs. Two cases run as real processes: an output FIFO (which would block an
``open``) and Ctrl-C in the middle of a run. Add a case by adding a spec file and a
``[[case]]`` entry; no code is needed (docs/reliability.md)."""

from __future__ import annotations

import hashlib
import json
import os
import select
import shutil
import signal
import stat
import subprocess
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

import pytest
from cli_runner import invoke_bounded

HERE = Path(__file__).resolve().parent
SPECS = HERE / "specs"
CASES: list[dict[str, Any]] = tomllib.loads((HERE / "cases.toml").read_text())["case"]
#: seconds one case may take before it counts as a hang
TIMEOUT = 30.0
#: what a Python or numpy repr leaves in a message: names and numbers are written as prose
#: (messages.listing, messages.shown_values, messages.given; issue 30)
PYTHON_REPRS = ("np.float64", "np.int64", "array(", "dtype=", "['", "{'", "[np.")


def _make(folder: Path, name: str, how: str) -> None:
    """Create the special file ``name`` in ``folder`` (kinds listed in cases.toml)."""
    p = folder / name
    p.parent.mkdir(parents=True, exist_ok=True)
    kind, _, arg = how.partition(":")
    if kind == "empty":
        p.write_bytes(b"")
    elif kind == "text":
        p.write_text(arg, encoding="utf-8")
    elif kind == "text-latin1":
        p.write_bytes(arg.encode("latin-1"))
    elif kind == "binary":
        p.write_bytes(bytes(range(256)) * 4)
    elif kind == "big":
        p.write_bytes(b"# " + b"x" * 1_100_000 + b"\n")
    elif kind == "dir":
        p.mkdir()
    elif kind == "fifo":
        os.mkfifo(p)
    elif kind == "symlink":
        os.symlink(arg, p)
    elif kind == "hardlink":
        os.link(folder / arg, p)
    elif kind == "copy":
        shutil.copyfile(SPECS / arg, p)
    elif kind == "bom":
        p.write_bytes(b"\xef\xbb\xbf" + (SPECS / arg).read_bytes())
    elif kind == "utf16":
        p.write_bytes((SPECS / arg).read_text().encode("utf-16"))
    else:  # pragma: no cover - a mistake in cases.toml
        raise ValueError(f"unknown make kind {how!r}")


def _snapshot(folder: Path) -> dict[str, tuple[str, str]]:
    """Every entry under ``folder``: (kind, content hash or link target); FIFOs are not read."""
    out: dict[str, tuple[str, str]] = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            p = Path(root) / name
            mode = os.lstat(p).st_mode
            rel = str(p.relative_to(folder))
            if stat.S_ISLNK(mode):
                out[rel] = ("link", os.readlink(p))
            elif stat.S_ISREG(mode):
                out[rel] = ("file", hashlib.sha256(p.read_bytes()).hexdigest())
            else:
                out[rel] = ("dir" if stat.S_ISDIR(mode) else "special", "")
    return out


def _flat(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_bad_input(case: dict[str, Any], tmp_path: Path) -> None:
    for name in case.get("files", []):
        shutil.copyfile(SPECS / name, tmp_path / name)
    for name, how in case.get("make", {}).items():
        _make(tmp_path, name, how)
    args = [a.replace("{d}", str(tmp_path)) for a in case["args"]]
    before = _snapshot(tmp_path)
    started = time.perf_counter()
    result, caught = invoke_bounded(args, case.get("timeout", TIMEOUT))
    took = time.perf_counter() - started
    output = result.output
    where = f"screwkit {' '.join(args)} ({took:.1f} s)\n{output}"
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        import traceback

        tb = "".join(traceback.format_exception(result.exception))
        pytest.fail(f"uncaught exception from {where}\n{tb}")
    assert "Traceback" not in output, where
    assert not caught, f"warnings {caught} from {where}"
    assert "RuntimeWarning" not in output, where
    assert result.exit_code == case["status"], where
    assert _flat(case["message"]) in _flat(output), where
    reprs = [r for r in PYTHON_REPRS if r in output]
    assert not reprs, f"Python reprs {reprs} in the message of {where}"
    after = _snapshot(tmp_path)
    allowed = set(case.get("outputs", []))
    changed = sorted(k for k in before if k not in allowed and after.get(k) != before[k])
    assert not changed, f"changed or removed {changed}: {where}"
    new = sorted(set(after) - set(before) - allowed)
    assert not new, f"left behind {new}: {where}"


def test_the_corpus_is_big_enough_and_every_spec_is_used() -> None:
    assert len(CASES) >= 60
    used = {n for c in CASES for n in c.get("files", [])}
    used |= {how.partition(":")[2] for c in CASES for how in c.get("make", {}).values()}
    assert {p.name for p in SPECS.glob("*.toml")} <= used


def _screwkit(args: list[str], **kw: Any) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "screwkit.cli.main", *args], text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kw)


def test_an_output_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    shutil.copyfile(SPECS / "rsrc.toml", tmp_path / "rsrc.toml")
    os.mkfifo(tmp_path / "out.json")
    proc = _screwkit(["analyze", str(tmp_path / "rsrc.toml"), "-o", str(tmp_path / "out.json")])
    try:
        out, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("screwkit blocked on an output FIFO")
    assert proc.returncode == 2 and "FIFO" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json", "rsrc.toml"]


def test_ctrl_c_leaves_no_file_and_no_traceback(tmp_path: Path) -> None:
    # a run of about 5 s (generic solver, 0.004° steps: 90,000 samples), interrupted once it is
    # under way: the process says when its imports are done, and the signal comes a second later
    spec = (SPECS / "rsrc.toml").read_text().replace('step = "10 deg"', 'step = "0.004 deg"')
    (tmp_path / "long.toml").write_text(spec)
    out = tmp_path / "out.json"
    start = ("import sys; from screwkit.cli.main import app; "
             "print('ready', file=sys.stderr, flush=True); app()")
    proc = subprocess.Popen(
        [sys.executable, "-c", start, "analyze", str(tmp_path / "long.toml"), "--method",
         "generic", "--json", "-o", str(out)],
        text=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert proc.stderr is not None
    ready, _, _ = select.select([proc.stderr], [], [], 60)
    assert ready and proc.stderr.readline().strip() == "ready"
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    try:
        _, stderr = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("screwkit did not stop on Ctrl-C")
    assert "Traceback" not in stderr, stderr
    if proc.returncode in (0, -2) and out.exists():  # it finished first: the file is whole
        # (-2: the signal came as the interpreter shut down, after the file was in place)
        json.loads(out.read_text())
    else:  # typer exits with 130 (128 + SIGINT) and says nothing
        assert proc.returncode in (1, 130) and not out.exists(), (proc.returncode, stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) in (["long.toml"], ["long.toml", "out.json"])


def test_ctrl_c_inside_a_c_callback_stops_the_run_without_a_traceback() -> None:
    """Ctrl-C that lands in a ctypes callback (where numba's compile cache notifies llvmlite)
    is dropped by Python with an "Exception ignored" traceback; the CLI's hook
    (cli/interrupts.py) prints nothing and delivers it to ordinary code, where it stops."""
    code = (
        "import ctypes, sys\n"
        "from screwkit.cli.interrupts import deliver_interrupts_from_callbacks\n"
        "if sys.argv[1] == 'hook': deliver_interrupts_from_callbacks()\n"
        "def cb(): raise KeyboardInterrupt\n"
        "f = ctypes.CFUNCTYPE(None)(cb)\n"
        "try:\n"
        "    f()\n"
        "    for _ in range(10**8): pass\n"
        "    print('ran on')\n"
        "except KeyboardInterrupt:\n"
        "    print('stopped')\n")
    runs = {how: subprocess.run([sys.executable, "-c", code, how], capture_output=True,
                                text=True, timeout=120) for how in ("hook", "bare")}
    assert runs["hook"].stdout.strip() == "stopped"
    assert runs["hook"].stderr == ""
    # without the hook Python drops the interrupt with a traceback: what the hook is for
    assert runs["bare"].stdout.strip() == "ran on"
    assert "Traceback" in runs["bare"].stderr
