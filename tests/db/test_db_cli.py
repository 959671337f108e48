"""``python -m bionav.db`` show/export and the export -> db=folder round trip."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from bionav.db.cli import main
from bionav.db.compose import compose_database
from bionav.db.database import ImageDatabase
from bionav.db.export import export_database
from bionav.db.loading import load_database
from bionav.geometry import PanoramaGeometry

REPO = Path(__file__).resolve().parents[2]


def make_db(*, quantised: bool = True, seed: int = 0) -> ImageDatabase:
    rng = np.random.default_rng(seed)
    cells = [(x, y) for x in range(3) for y in range(4) if (x, y) not in {(1, 2), (2, 0)}]
    images = rng.random((len(cells), 7, 40)).astype(np.float32)
    if quantised:
        images = (np.rint(images * 255).astype(np.float32) / np.float32(255))
    geometry = PanoramaGeometry(40, 7, horizon_row=4.25, rad_per_row=0.0375)
    return ImageDatabase("roundtrip", images, np.array(cells), (3, 5), geometry, spacing_m=0.3)


def load_folder_db(overrides):
    composed = compose_database("folder", overrides[1:])
    return load_database(composed.db, data_dir=composed.data_dir, cache_dir=composed.cache_dir)


@pytest.mark.parametrize("quantised", [True, False])
def test_export_round_trips_through_db_folder(tmp_path, quantised):
    db = make_db(quantised=quantised)
    overrides = export_database(db, tmp_path / "out")
    assert overrides[0] == "db=folder"
    back = load_folder_db(overrides)
    assert back.grid_shape == db.grid_shape and back.spacing_m == db.spacing_m
    assert back.geometry == db.geometry
    order = [back.index_of(x, y) for x, y in db.positions]
    if quantised:  # 8-bit PNG, lossless
        np.testing.assert_array_equal(back.images[order], db.images)
    else:  # 16-bit PNG
        np.testing.assert_allclose(back.images[order], db.images, atol=0.5 / 65535 + 1e-7)


def test_export_writes_bielefeld_convention(tmp_path):
    db = make_db()
    export_database(db, tmp_path)
    x, y = db.positions[3]
    disk = cv2.imread(str(tmp_path / f"{x}_{y}.png"), cv2.IMREAD_UNCHANGED).astype(np.float32) / 255
    # disk column c looks clockwise: disk[:, c] = canonical[:, (-c) mod W]
    np.testing.assert_array_equal(disk, db.images[3][:, (-np.arange(40)) % 40])


def test_export_refuses_to_mix_databases(tmp_path):
    from bionav.errors import UserError

    export_database(make_db(), tmp_path)
    with pytest.raises(UserError, match="--force"):
        export_database(make_db(seed=1), tmp_path)
    export_database(make_db(seed=1), tmp_path, overwrite=True)


def test_cli_show_and_export_in_process(tmp_path, capsys):
    export_database(make_db(), tmp_path / "db")
    assert main(["show", "folder", "--out", str(tmp_path / "show"), f"db.path={tmp_path / 'db'}"]) == 0
    sheet = cv2.imread(str(tmp_path / "show" / "folder_contact.png"), cv2.IMREAD_UNCHANGED)
    grid = cv2.imread(str(tmp_path / "show" / "folder_grid.png"), cv2.IMREAD_UNCHANGED)
    assert sheet is not None and sheet.shape[1] > 3 * 40 and grid is not None
    out = capsys.readouterr().out
    assert "10 images" in out and "3 x 4 grid" in out
    assert main(["export", "folder", str(tmp_path / "again"), f"db.path={tmp_path / 'db'}"]) == 0
    assert len(list((tmp_path / "again").glob("*_*.png"))) == 10


def test_cli_errors_are_one_message_exit_2(tmp_path, capsys):
    assert main(["show", "no_such_db"]) == 2
    err = capsys.readouterr().err
    assert "unknown database 'no_such_db'" in err and "hall1" in err and "Traceback" not in err
    assert main(["show", "uni", f"data_dir={tmp_path}"]) == 2
    err = capsys.readouterr().err
    assert str((tmp_path / "uni").resolve()) in err and "db=sim_uni" in err
    assert main(["show", "folder", f"db.path={tmp_path}", "db.spacing_m=far"]) == 2
    assert "spacing_m" in capsys.readouterr().err


def test_cli_subprocess_help_and_clean_failure(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(REPO))
    run = subprocess.run([sys.executable, "-m", "bionav.db", "--help"], capture_output=True, text=True,
                         cwd=REPO, env=env, timeout=120)
    assert run.returncode == 0
    for name in ("original", "moeller1", "roeben1", "hall2", "uni", "folder"):
        assert name in run.stdout
    run = subprocess.run([sys.executable, "-m", "bionav.db", "show", "original", f"data_dir={tmp_path}"],
                         capture_output=True, text=True, cwd=tmp_path, env=env, timeout=120)
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and "BIONAV_DATA" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
