"""Where ``screwkit export`` samples the motion (``--at`` merged into the sweep) and what it
says when a format's library is missing."""

import importlib.util

import numpy as np
import pytest

from screwkit.exchange.export import export_format
from screwkit.exchange.samples import ExportError, assembled_runs, export_samples


def test_at_values_are_merged_into_the_sweep_in_its_order():
    x = np.arange(0.0, 37.0) * 10
    s = export_samples(x, [45.0, 40.0, 360.0, 45.0 + 1e-11])
    assert np.array_equal(s.inputs[s.sweep], x)  # the sweep's own samples, unchanged
    assert len(s.inputs) == 38  # only 45 is new: 40 and 360 are samples, 45 + 1e-11 is 45
    assert s.inputs[s.at].tolist() == [45.0, 40.0, 360.0, 45.0]
    down = export_samples(x[::-1], [45.0, 5.0])
    assert np.array_equal(down.inputs[down.sweep], x[::-1])
    assert np.all(np.diff(down.inputs) < 0) and down.inputs[down.at].tolist() == [45.0, 5.0]


def test_at_outside_the_sweep_is_refused():
    with pytest.raises(ExportError, match=r"--at 400 deg lies outside .* \(0…360 deg\)"):
        export_samples(np.arange(0.0, 37.0) * 10, [400.0], ["400 deg"], " (0…360 deg)")


def test_runs_of_assembled_samples():
    ok = np.array([True, True, False, True, False, False, True, True, True])
    assert assembled_runs(ok) == [(0, 2), (3, 4), (6, 9)]
    assert assembled_runs(np.zeros(3, dtype=bool)) == []


def test_missing_library_names_the_extra(monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "ezdxf" else real(name, *a))
    with pytest.raises(ExportError, match=r"DXF export needs ezdxf: pip install 'screwkit\[cad\]'"):
        export_format("dxf")
    assert export_format("GLB") == "gltf"
