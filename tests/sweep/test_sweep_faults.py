"""Dask faults, each caused for real on the embedded cluster (docs/sweeps.md, "Faults"):

- a worker process killed (``os.kill``, SIGKILL) while the cluster starts: the start is tried
  again and the sweep finishes, with one note; workers that die at every start: one sentence,
  exit 2, after a bounded number of attempts;
- a worker killed mid-sweep: it is replaced, every row equals the in-process run's, one note;
- SIGTERM to the command (as ``kill`` sends it), SIGTERM and SIGINT to its whole process group
  (as a batch system and Ctrl-C in a terminal send them): one line, the checkpoint kept,
  how to resume, no traceback, no leaked semaphores;
- a task that kills every worker that runs it, a scheduler lost mid-sweep: one sentence (and,
  for the sweep, how to resume);
- a rerun without ``--resume`` refuses a checkpoint holding finished designs (``--fresh``
  discards it, and says so).

The tests wait on conditions (a file the worker writes, batches in the checkpoint), never on
fixed delays; each has a deadline so a fault in the fault handling fails instead of hanging.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import psutil  # comes with distributed (the [sweep] extra)
import pytest
from sweep_helpers import EXAMPLES, runner

from screwkit.cli.main import app
from screwkit.sweep import EngineConfig, EngineError, define_sweep, run_sweep, start_engine
from screwkit.sweep.checkpoint import CheckpointError, checkpoint_folder
from screwkit.sweep.table import read_table

SPEC = EXAMPLES / "rsrc_fig7_dynamics.toml"
SRC = Path(__file__).resolve().parents[2] / "src"

#: a worker preload: the first worker process to start writes its pid to $HOLD_MARKER and
#: waits there (to be killed); any other starts normally
HOLD_FIRST = """
import os, time
try:
    fd = os.open(os.environ["HOLD_MARKER"], os.O_CREAT | os.O_EXCL | os.O_WRONLY)
except FileExistsError:
    pass
else:
    os.write(fd, str(os.getpid()).encode())
    os.close(fd)
    time.sleep(600)
"""
#: a worker preload: every worker process dies while starting
DIE = "import os\nos._exit(3)\n"


def _sweep_command(out: Path, designs: int, workers: int, *extra: str) -> list[str]:
    return [sys.executable, "-m", "screwkit.cli.main", "sweep", str(SPEC), "--vary",
            f"d2=4.2:4.8:{designs}", "--job", "dynamics", "-o", str(out), "--workers",
            str(workers), "--batch-size", "1", *extra]


def _lines(text: str) -> list[str]:
    """The messages of ``text``, one per item: the CLI wraps a message between words at the
    terminal width with its continuation lines indented by two (issue 30, the 80-column
    promise); each continuation is joined back to its message with the space it replaced."""
    out: list[str] = []
    for line in text.splitlines():
        if line.startswith("  ") and out:
            out[-1] += " " + line.strip()
        else:
            out.append(line)
    return out


def _start(cmd: list[str], preload: Path | None = None, marker: Path | None = None,
           group: bool = False) -> subprocess.Popen[str]:
    env = {**os.environ, "COLUMNS": "200", "PYTHONPATH": str(SRC)}
    if preload is not None:
        env["DASK_DISTRIBUTED__WORKER__PRELOAD"] = f'["{preload}"]'
    if marker is not None:
        env["HOLD_MARKER"] = str(marker)
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=group)


def _wait_for(condition: Callable[[], bool], proc: subprocess.Popen[str], what: str,
              seconds: float = 60) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            out, err = proc.communicate()
            pytest.fail(f"never saw {what} (exit {proc.returncode}):\n{out}\n{err}")
        time.sleep(0.05)


def _batches(out: Path) -> int:
    return len(list(checkpoint_folder(out).glob("batch-*.json")))


def _finish(proc: subprocess.Popen[str]) -> tuple[str, str]:
    try:
        return proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        pytest.fail(f"the command did not end:\n{out}\n{err}")


#: designs of the mid-sweep tests: enough that a signal sent once two batches are kept lands
#: long before the last (one design a task, some 10 ms each)
DESIGNS = 100


def _reference(folder: Path, designs: int) -> list[dict]:
    definition = define_sweep(SPEC, [f"d2=4.2:4.8:{designs}"], "dynamics")
    run_sweep(definition, folder / "reference.csv", EngineConfig(workers=0))
    return read_table(folder / "reference.csv")


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> list[dict]:
    """The mid-sweep tests' table, computed in this process without Dask."""
    return _reference(tmp_path_factory.mktemp("reference"), DESIGNS)


def test_a_worker_killed_while_the_cluster_starts_is_retried(tmp_path):
    preload, marker = tmp_path / "hold_first.py", tmp_path / "held.pid"
    preload.write_text(HOLD_FIRST)
    out = tmp_path / "t.csv"
    proc = _start(_sweep_command(out, 3, 1), preload, marker)
    _wait_for(lambda: marker.exists() and marker.read_text() != "", proc,
              "a worker process starting")
    os.kill(int(marker.read_text()), signal.SIGKILL)  # the worker, while it starts
    stdout, err = _finish(proc)
    assert proc.returncode == 0, err
    assert _lines(err) == [
        "note: the embedded Dask cluster started at the second attempt (a worker process "
        "stopped while starting: Nanny failed to start worker process)"]
    assert read_table(out) == _reference(tmp_path, 3)  # the same rows as in this process


def test_workers_that_die_at_every_start_stop_the_command_with_one_sentence(tmp_path):
    preload = tmp_path / "die.py"
    preload.write_text(DIE)
    out = tmp_path / "t.csv"
    t0 = time.monotonic()
    proc = _start(_sweep_command(out, 3, 1), preload)
    stdout, err = _finish(proc)
    assert proc.returncode == 2, err
    assert _lines(err) == [
        "error: the embedded Dask cluster of 1 worker process(es) did not start in 3 attempts "
        "(a worker process stopped while starting: Nanny failed to start worker process); "
        "check the machine's free memory and run again, with fewer --workers, or with "
        "--workers 0 to run in this process"]
    assert not out.exists() and stdout == ""
    assert time.monotonic() - t0 < 60  # bounded: three attempts, not a retry loop


def test_a_worker_lost_mid_sweep_is_replaced_and_reported(tmp_path, reference):
    out = tmp_path / "t.csv"
    proc = _start(_sweep_command(out, DESIGNS, 2))
    _wait_for(lambda: _batches(out) >= 1, proc, "a finished batch")
    workers = [p for p in psutil.Process(proc.pid).children()
               if "spawn_main" in " ".join(p.cmdline())]
    assert len(workers) == 2
    os.kill(workers[0].pid, signal.SIGKILL)
    stdout, err = _finish(proc)
    assert proc.returncode == 0, err
    assert len(_lines(err)) == 1, err
    assert _lines(err)[0].startswith("note: 1 worker process was lost"), err
    assert _lines(err)[0].endswith("during the run; every design was evaluated"), err
    assert read_table(out) == reference  # every row, the same values


@pytest.mark.parametrize(("name", "group", "code", "how"), [
    ("SIGTERM", False, 143, "terminated (SIGTERM)"),  # kill PID
    ("SIGTERM", True, 143, "terminated (SIGTERM)"),  # a batch system stopping the job
    ("SIGINT", True, 130, "interrupted"),  # Ctrl-C in a terminal: the whole process group
])
def test_a_stopped_sweep_says_so_in_one_line(tmp_path, request, name, group, code, how):
    out = tmp_path / "t.csv"
    cmd = _sweep_command(out, DESIGNS, 1)
    proc = _start(cmd, group=group)
    _wait_for(lambda: _batches(out) >= 2, proc, "two finished batches")
    sig = getattr(signal, name)
    if group:
        os.killpg(proc.pid, sig)
    else:
        proc.send_signal(sig)
    stdout, err = _finish(proc)
    assert proc.returncode == code, err
    folder = checkpoint_folder(out)
    assert _lines(err) == [
        f"{how}: no table written; the finished designs are kept in {folder} — run the same "
        "command with --resume to continue"]  # no traceback, no leaked semaphores
    assert not out.exists() and _batches(out) >= 2
    if not group:  # and it does continue (the Ctrl-C test resumes too)
        r = runner.invoke(app, [*cmd[3:-4], "--workers", "0", "--resume"])
        assert r.exit_code == 0, r.output
        assert read_table(out) == request.getfixturevalue("reference")


def test_a_scheduler_lost_mid_sweep_stops_with_one_sentence(tmp_path, reference):
    dask_command = str(Path(sys.executable).with_name("dask"))
    info, out = tmp_path / "scheduler.json", tmp_path / "t.csv"
    env = {**os.environ, "PYTHONWARNINGS": "ignore"}
    scheduler = subprocess.Popen(
        [dask_command, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
         "--scheduler-file", str(info)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        env=env, text=True)
    worker = None
    try:
        _wait_for(lambda: info.exists() and "address" in info.read_text(), scheduler,
                  "the scheduler's address")
        address = json.loads(info.read_text())["address"]
        worker = subprocess.Popen(
            [dask_command, "worker", address, "--nthreads", "1", "--nworkers", "1", "--host",
             "127.0.0.1", "--no-dashboard"], stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, env=env)
        cmd = _sweep_command(out, DESIGNS, 1)
        proc = _start([*cmd[:-4], "--scheduler", address, "--batch-size", "1"])
        _wait_for(lambda: _batches(out) >= 2, proc, "two finished batches")
        scheduler.kill()
        stdout, err = _finish(proc)
    finally:
        for p in (scheduler, worker):
            if p is not None:
                p.kill()
                p.wait(timeout=30)
    assert proc.returncode == 2, err
    folder = checkpoint_folder(out)
    assert len(_lines(err)) == 1, err
    [line] = _lines(err)
    assert line.startswith(f"error: the run lost its connection to the Dask scheduler "
                           f"{address} ("), line
    assert line.endswith("); check that the scheduler is running and run again; the finished "
                         f"designs are kept in {folder} — run the same command with --resume "
                         "to continue"), line
    r = runner.invoke(app, [*cmd[3:-4], "--workers", "0", "--resume"])
    assert r.exit_code == 0, r.output
    assert read_table(out) == reference


def test_sigterm_is_an_interrupt_with_its_own_exit_code():
    """What ``tolerance`` and ``synthesize`` get too (their engine is entered with it)."""
    import typer

    from screwkit.cli.sweep_cmd import sigterm_as_interrupt, stopped

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt) as caught, sigterm_as_interrupt():
        signal.raise_signal(signal.SIGTERM)
        pytest.fail("SIGTERM did not interrupt")
    assert signal.getsignal(signal.SIGTERM) == before  # restored
    with pytest.raises(typer.Exit) as stop:
        stopped(caught.value, "nothing written")
    assert stop.value.exit_code == 143
    with pytest.raises(typer.Exit) as stop:
        stopped(KeyboardInterrupt(), "nothing written")  # Ctrl-C
    assert stop.value.exit_code == 130


def test_a_task_that_kills_every_worker_running_it_stops_with_one_sentence():
    import dask
    import distributed  # noqa: F401 - its config defaults must exist before dask.config.set:
    # a block that creates the "distributed" key deletes it on leaving, defaults and all, and
    # the next embedded cluster in this process fails with KeyError('distributed')

    # one death is enough here (Dask's default tries it on four workers in turn)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            start_engine(EngineConfig(workers=1)) as engine:
        with pytest.raises(EngineError, match=r"^task 1 of 1 stopped every worker process "
                                              r"that ran it \(each died while running it"):
            engine.map(os._exit, 3, [()], lambda i, r: None)  # os._exit(3) on the worker


def test_a_rerun_without_resume_refuses_the_checkpoint(tmp_path):
    out = tmp_path / "t.csv"
    args = ["sweep", str(SPEC), "--vary", "d2=4.2:4.8:6", "--job", "dynamics", "-o", str(out),
            "--workers", "0", "--batch-size", "2"]
    definition = define_sweep(SPEC, ["d2=4.2:4.8:6"], "dynamics")

    def stop_after_two_batches(done: int, total: int, computed: int) -> None:
        if computed >= 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(definition, out, EngineConfig(workers=0), batch=2,
                  progress=stop_after_two_batches)
    folder = checkpoint_folder(out)
    kept = sorted((p.name, p.read_bytes()) for p in folder.iterdir())
    r = runner.invoke(app, args)
    assert r.exit_code == 2
    assert _lines(r.stderr) == [
        f"error: {folder} holds 4 finished design(s) of an interrupted run of this sweep; pass "
        "--resume to continue it, or --fresh to discard them and start again"]
    assert sorted((p.name, p.read_bytes()) for p in folder.iterdir()) == kept  # untouched
    r = runner.invoke(app, [*args, "--resume", "--fresh"])
    assert r.exit_code == 2 and "pass one of them" in " ".join(_lines(r.stderr))
    r = runner.invoke(app, [*args, "--fresh"])
    assert r.exit_code == 0, r.output
    assert _lines(r.stderr) == [
        f"note: --fresh: discarded the 4 finished design(s) of an earlier run kept in {folder}"]
    assert "│        6 │       0 │" in r.stdout  # all 6 computed, none resumed
    assert not folder.exists() and len(read_table(out)) == 6


def test_a_checkpoint_without_finished_designs_is_replaced_silently(tmp_path):
    out = tmp_path / "t.csv"
    definition = define_sweep(SPEC, ["d2=4.2:4.8:3"], "dynamics")
    with pytest.raises(KeyboardInterrupt):  # stopped before its first batch was kept
        run_sweep(definition, out, EngineConfig(workers=0),
                  progress=lambda d, t, c: (_ for _ in ()).throw(KeyboardInterrupt))
    assert checkpoint_folder(out).is_dir() and _batches(out) == 0
    result = run_sweep(definition, out, EngineConfig(workers=0))  # nothing to lose
    assert result.computed == 3 and result.notes == ()
    with pytest.raises(CheckpointError, match="pass one of them"):
        run_sweep(definition, out, EngineConfig(workers=0), resume=True, fresh=True)
