"""The plan's machine calibration (issue 42): cached per CPU, factors against the reference machine."""

from __future__ import annotations

import json

import pytest

from bionav.errors import UserError
from bionav.thesis import calibration as cal


def test_calibration_is_measured_once_and_cached_per_cpu(tmp_path, monkeypatch):
    monkeypatch.setenv("BIONAV_CACHE", str(tmp_path))
    calls = []

    def fake():
        calls.append(1)
        return {**{f: 2.0 * cal.REFERENCE[f] for f in cal.FAMILIES}, "machine": "test", "cpu": "x", "version": 1}

    monkeypatch.setattr(cal, "measure_machine", fake)
    first = cal.machine_calibration()
    again = cal.machine_calibration()
    assert first == again and len(calls) == 1
    path = cal.cache_path()
    assert path.parent == tmp_path / "calibration" and json.loads(path.read_text()) == first
    f = cal.factors()
    assert all(f[fam] == pytest.approx(2.0) for fam in cal.FAMILIES) and "test" in f["source"]
    cal.machine_calibration(refresh=True)
    assert len(calls) == 2


def test_a_real_calibration_times_every_family():
    out = cal.measure_machine()
    assert all(0 < out[f] < 10_000 for f in cal.FAMILIES) and out["machine"] and out["cpu"]


def test_cpu_factor_and_calibration_files(tmp_path):
    f = cal.factors(cpu_factor=1.5)
    assert all(f[fam] == 1.5 for fam in cal.FAMILIES) and f["source"] == "--cpu-factor 1.5"
    good = tmp_path / "other.json"
    good.write_text(json.dumps({**{fam: cal.REFERENCE[fam] / 2 for fam in cal.FAMILIES}, "machine": "other"}))
    assert cal.factors(cal.load_calibration(str(good)))["minwarping"] == pytest.approx(0.5)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"minwarping": -1}))
    with pytest.raises(UserError, match="lacks a positive CPU time"):
        cal.load_calibration(str(bad))
    with pytest.raises(UserError, match="cannot read it"):
        cal.load_calibration(str(tmp_path / "missing.json"))
