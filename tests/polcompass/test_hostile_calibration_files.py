"""Calibration files a user hands bionav (issue 45): capped before they are read, every field checked after.

NaN, infinity, zero gains, ragged lists, a unit index of -1, another unit count, gigabytes (a sparse file,
``/dev/zero``): each is one message naming the file, the field and the allowed values, exit status 2, before
the session starts, and no run directory is left behind -- never a "completed" run with NaN headings.
"""

from __future__ import annotations

import json

import pytest
from helpers import assert_fails_cleanly, external_data, run_bionav

NOMINAL = {"center_v": [2.5, 2.5, 2.5], "volts_per_decade": [0.5, 0.5, 0.5], "unit_angles": [0.0, 1.047, 2.094]}

#: name -> (file text, or a special file, and the words the message must hold)
COMPASS_CASES = {
    "nan": ('{"center_v": [NaN, 2.5, 2.5], "volts_per_decade": [0.5, 0.5, 0.5], "unit_angles": [0, 1, 2]}',
            ["field 'center_v' holds nan at [0]", "allowed: a finite number >= 0 and <= 5"]),
    "infinity": ('{"center_v": [2.5, 2.5, 2.5], "volts_per_decade": [0.5, 0.5, 0.5], "unit_angles": [0, Infinity, 2]}',
                 ["field 'unit_angles' holds inf at [1]"]),
    "zero_gain": (json.dumps({**NOMINAL, "volts_per_decade": [0.5, 0.0, 0.5]}),
                  ["field 'volts_per_decade' holds 0 at [1]", "allowed: a finite number >= 0.01"]),
    "ragged": (json.dumps({**NOMINAL, "unit_angles": [[0.0, 1.0], [2.0]]}), ["field 'unit_angles' is a ragged list"]),
    "two_units": (json.dumps({k: v[:2] for k, v in NOMINAL.items()}),
                  ["field 'center_v' has 2 values", "one per unit of this compass (3 units)"]),
    "volts_beyond_the_rails": (json.dumps({**NOMINAL, "center_v": [2.5, 7.0, 2.5]}), ["field 'center_v' holds 7 at [1]"]),
    "text": (json.dumps({**NOMINAL, "center_v": "2.5"}), ["field 'center_v'"]),
    "list": ("[1, 2, 3]", ["is a JSON list, not an object"]),
    "nested_deeply": ("[" * 100_000 + "]" * 100_000, ["nests lists or objects thousands of levels deep"]),
    "gigabytes": ("sparse", ["is 3 GiB, more than the 16 MiB"]),
    "dev_zero": ("/dev/zero", ["is a device, not a file"]),
}


def _file(tmp_path, text: str):
    if text == "/dev/zero":
        return "/dev/zero"
    path = tmp_path / "calibration.json"
    if text == "sparse":
        with open(path, "wb") as f:
            f.truncate(3 * 2**30)  # 3 GiB that take no disk
    else:
        path.write_text(text)
    return str(path)


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(COMPASS_CASES))
def test_a_bad_compass_calibration_file_is_refused_before_the_session(tmp_path, case):
    text, needles = COMPASS_CASES[case]
    path = _file(tmp_path, text)
    proc = run_bionav("experiment=pol_compass", "mode=rotation", "experiment.calibration=file",
                      f"experiment.calibration_path={path}", cwd=tmp_path)  # into the default outputs/<date>/<time>
    assert_fails_cleanly(proc, path, *needles, code=2, max_seconds=120)
    assert not (tmp_path / "outputs").exists()  # no run directory, no empty outputs/ either


def _array(**change) -> str:
    k, p = 8, 4
    data = {"schema": "bionav.pol_array_calibration/1", "units": k, "photodiodes": p, "gain": [[1.0] * p] * k,
            "gain_log_sigma": [[None] * p] * k, "angle_offset_deg": [[0.0] * p] * k, "angle_sigma_deg": [[None] * p] * k,
            "azimuth_offset_deg": [0.0] * k, "azimuth_sigma_deg": [None] * k, "calibrated_units": [0, 1],
            "n_sessions": [1] * k, "sessions": ["s"]}
    return json.dumps({**data, **change})


ARRAY_CASES = {
    "unit_index_minus_one": (_array(calibrated_units=[-1]), ["field 'calibrated_units' holds -1", "<= 7"]),
    "zero_gain": (_array(gain=[[1.0, 0.0, 1.0, 1.0]] + [[1.0] * 4] * 7), ["field 'gain' holds 0 at [0, 1]"]),
    "nan_gain": (_array(gain=[[1.0] * 4] * 7 + [[1.0, 1.0, 1.0, float("nan")]]), ["field 'gain' holds nan at [7, 3]"]),
    "a_billion_units": (_array(units=10**9), ["field 'units' holds 1e+09", "<= 64"]),
    "ragged": (_array(gain=[[1.0] * 4] * 7 + [[1.0]]), ["field 'gain' is a ragged list"]),
    "angle_offset": (_array(angle_offset_deg=[[1e9] * 4] * 8), ["field 'angle_offset_deg' holds 1e+09", "<= 180"]),
    "gigabytes": ("sparse", ["is 3 GiB, more than the 16 MiB"]),
    "dev_zero": ("/dev/zero", ["is a device, not a file"]),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(ARRAY_CASES))
def test_a_bad_recordings_calibration_file_is_refused_before_the_recordings_load(tmp_path, case):
    data = external_data() / "celestial-compass"
    if not data.is_dir():
        pytest.skip(f"the POL-OP recordings are not at {data}")
    text, needles = ARRAY_CASES[case]
    path = _file(tmp_path, text)
    proc = run_bionav("experiment=pol_recordings", f"recordings.path={data}", f"recordings.calibration={path}",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, path, *needles, code=2, max_seconds=120)
    assert not (tmp_path / "run").exists()
