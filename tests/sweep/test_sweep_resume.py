"""Ctrl-C leaves no table (and no temporary file) but keeps the finished batches; --resume
computes only the rest and writes the same bytes as an uninterrupted run; a checkpoint of
another sweep is refused. Also the command line end to end: Ctrl-C on ``screwkit sweep``, the
picture and the demo index."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest
from sweep_helpers import EXAMPLES, runner

from screwkit.cli.main import app
from screwkit.report.sweep_pictures import png_text, sweep_pictures
from screwkit.sweep import EngineConfig, define_sweep, run_sweep
from screwkit.sweep.checkpoint import CheckpointError, checkpoint_folder

SPEC = EXAMPLES / "rsrc_fig7_dynamics.toml"
IN_PROCESS = EngineConfig(workers=0)


def test_interrupted_sweep_resumes_to_the_same_table(tmp_path):
    definition = define_sweep(SPEC, ["d2=4.2:4.8:4", "e=0.5:1.5:3"], "dynamics")
    whole = tmp_path / "whole.parquet"
    run_sweep(definition, whole, IN_PROCESS, batch=3)
    out = tmp_path / "out.parquet"

    def stop_after_two_batches(done: int, total: int, computed: int) -> None:
        if computed >= 6:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(definition, out, IN_PROCESS, batch=3, progress=stop_after_two_batches)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".out.parquet.")] == \
        [".out.parquet.sweep"]  # the checkpoint only, no temporary table
    assert len(list(checkpoint_folder(out).glob("batch-*.json"))) == 2
    result = run_sweep(definition, out, IN_PROCESS, batch=5, resume=True)
    assert (result.resumed, result.computed) == (6, 6)
    assert out.read_bytes() == whole.read_bytes()
    assert not checkpoint_folder(out).exists()  # removed once the table is written


def test_resume_refuses_a_checkpoint_of_another_sweep(tmp_path):
    out = tmp_path / "t.csv"
    first = define_sweep(SPEC, ["d2=4.2:4.8:4"], "dynamics")
    with pytest.raises(KeyboardInterrupt):
        run_sweep(first, out, IN_PROCESS, batch=1,
                  progress=lambda d, t, c: (_ for _ in ()).throw(KeyboardInterrupt) if c else None)
    other = define_sweep(SPEC, ["d2=4.2:4.9:4"], "dynamics")
    with pytest.raises(CheckpointError, match="belongs to another sweep"):
        run_sweep(other, out, IN_PROCESS, resume=True)
    with pytest.raises(CheckpointError, match="another sweep writing the same output"):
        run_sweep(other, out, IN_PROCESS)  # without --fresh it is not discarded silently
    result = run_sweep(other, out, IN_PROCESS, fresh=True)
    assert result.resumed == 0 and out.exists()
    assert result.notes == (f"--fresh: discarded the 1 finished design(s) of an earlier run "
                            f"kept in {checkpoint_folder(out)}",)


def test_ctrl_c_on_the_command_keeps_no_table(tmp_path):
    out = tmp_path / "big.parquet"
    cmd = [sys.executable, "-m", "screwkit.cli.main", "sweep", str(SPEC), "--vary",
           "d2=4.2:4.8:200", "--job", "dynamics", "-o", str(out), "--workers", "0",
           "--batch-size", "2"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "COLUMNS": "200"})
    folder = checkpoint_folder(out)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list(folder.glob("batch-*.json"))) < 2:
        time.sleep(0.1)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "--resume" in err and "Traceback" not in err
    assert not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name != folder.name]
    r = runner.invoke(app, [*cmd[3:], "--resume"])
    assert r.exit_code == 0, r.output
    assert "200" in r.stdout and out.exists()


def test_plots_and_the_demo_index(tmp_path):
    from screwkit.report.html import write_index

    for vary, name in ((["d2=4.2:4.8:3"], "line.png"), (["d2=4.2:4.8:3", "e=0.5:1.5:2"], "heat.png"),
                       (["d2=4.2:4.8:2", "e=0.5:1.5:2", "a=2.9,3.1"], "matrix.png")):
        r = runner.invoke(app, ["sweep", str(SPEC), *sum((["--vary", v] for v in vary), []),
                                "--job", "dynamics", "-o", str(tmp_path / f"{name}.csv"),
                                "--plot", str(tmp_path / name), "--workers", "0"])
        assert r.exit_code == 0, r.output
        text = png_text(tmp_path / name)
        assert text["Software"] == "screwkit sweep"
        assert "shaking_force.rms" in text["Description"]
    r = runner.invoke(app, ["sweep", str(SPEC), "--vary", "d2=4.2:4.8:4", "--vary", "e=0.5:1:2",
                            "--sample", "lhs:8", "-o", str(tmp_path / "x.csv"), "--workers", "0"])
    assert r.exit_code == 2 and "START:STOP" in r.stderr
    (tmp_path / "other.png").write_bytes(b"\x89PNG\r\n\x1a\n")  # not a sweep picture
    assert [p["file"] for p in sweep_pictures(tmp_path)] == ["heat.png", "line.png", "matrix.png"]
    page = write_index(tmp_path, []).read_text()
    assert "Design sweeps" in page and "<img src='heat.png'" in page


def test_latin_hypercube_designs_are_reproducible_and_stratified(tmp_path):
    import numpy as np

    a = define_sweep(SPEC, ["d2=4:5", "e=0.5:1.5"], "dynamics", sample="lhs:20", seed=7)
    b = define_sweep(SPEC, ["d2=4:5", "e=0.5:1.5"], "dynamics", sample="lhs:20", seed=7)
    c = define_sweep(SPEC, ["d2=4:5", "e=0.5:1.5"], "dynamics", sample="lhs:20", seed=8)
    assert np.array_equal(a.designs.values, b.designs.values)
    assert not np.array_equal(a.designs.values, c.designs.values)
    unit = (a.designs.values - [4.0, 0.5]) / [1.0, 1.0]
    for k in range(2):  # one design in each of the 20 strata of every key
        assert sorted(np.floor(unit[:, k] * 20).astype(int).tolist()) == list(range(20))
