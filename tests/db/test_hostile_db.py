"""Hostile database folders (issue 13 items 4 and 10) through ``python -m bionav db=folder ...``.

Each bad case: non-zero exit, one ``bionav: error:`` paragraph naming the file (or key) and the
fix, no traceback, and a metrics.json that is strict JSON (no NaN).
"""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from helpers import assert_fails_cleanly, run_bionav

from bionav.db.imageio import write_image

SIZE = (32, 8)  # W, H of the test images


def make_folder(folder, cells, *, seed=0):
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    for x, y in cells:
        write_image(folder / f"{x}_{y}.png", rng.random((SIZE[1], SIZE[0])))
    return folder


def grid(nx, ny):
    return [(x, y) for x in range(nx) for y in range(ny)]


def run_folder(tmp_path, folder, *extra):
    return run_bionav("db=folder", f"db.path={folder}", "homing=mfdid", f"hydra.run.dir={tmp_path / 'run'}", *extra,
                      cwd=tmp_path)


def strict_metrics(run_dir):
    """metrics.json parsed strictly: NaN or Infinity are not JSON."""
    def no_constants(name):
        raise ValueError(f"metrics.json holds {name}")

    return json.loads((run_dir / "metrics.json").read_text(), parse_constant=no_constants)


def test_stray_far_file_is_named_instead_of_allocating_a_huge_grid(tmp_path):
    folder = make_folder(tmp_path / "db", grid(3, 3))
    write_image(folder / "99999_99999.png", np.zeros((SIZE[1], SIZE[0])))
    proc = run_folder(tmp_path, folder)
    assert_fails_cleanly(proc, "99999_99999.png", "100000 x 100000", "db.grid_shape")


@pytest.mark.slow
def test_stray_file_outside_declared_grid_can_be_skipped(tmp_path):
    folder = make_folder(tmp_path / "db", grid(3, 3))
    write_image(folder / "99999_99999.png", np.zeros((SIZE[1], SIZE[0])))
    proc = run_folder(tmp_path, folder, "db.grid_shape=[3,3]")
    assert_fails_cleanly(proc, "99999_99999.png", "outside the declared 3 x 3 grid", "db.on_bad_image=skip")
    proc = run_folder(tmp_path, folder, "db.grid_shape=[3,3]", "db.on_bad_image=skip", "experiment.snapshots=[0]")
    assert proc.returncode == 0, proc.stderr
    assert "skipping" in proc.stdout + proc.stderr and "99999_99999.png" in proc.stdout + proc.stderr


def test_one_image_database_is_a_user_error_not_nan(tmp_path):
    folder = make_folder(tmp_path / "db", [(0, 0)])
    proc = run_folder(tmp_path, folder)
    assert_fails_cleanly(proc, "has 1 usable image(s)", "at least 2", "no run directory was left behind")
    assert not (tmp_path / "run").exists()  # refused at start (issue 45)
    (tmp_path / "run").mkdir()  # into a folder the user made, the failure is recorded there
    proc = run_folder(tmp_path, folder)
    assert_fails_cleanly(proc, "has 1 usable image(s)", "at least 2")
    metrics = strict_metrics(tmp_path / "run")
    assert metrics["status"] == "failed" and "at least 2" in metrics["error"]


@pytest.mark.slow
def test_directory_named_like_an_image_is_reported(tmp_path):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    (folder / "1_1.png").unlink()
    (folder / "1_1.png").mkdir()
    proc = run_folder(tmp_path, folder)
    assert_fails_cleanly(proc, "1_1.png", "is a directory", "db.on_bad_image=skip")
    proc = run_folder(tmp_path, folder, "db.on_bad_image=skip", "experiment.snapshots=[0]")
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout + proc.stderr
    assert "1_1.png" in out and "is a directory" in out  # the warning names it
    assert strict_metrics(tmp_path / "run")["n_images"] == 3


def test_symlink_loop_named_like_an_image_is_reported(tmp_path):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    (folder / "1_0.png").unlink()
    os.symlink("1_0.png", folder / "1_0.png")  # points at itself
    assert_fails_cleanly(run_folder(tmp_path, folder), "1_0.png", "symbolic-link loop")


@pytest.mark.slow
def test_dangling_symlink_named_like_an_image_is_reported(tmp_path):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    (folder / "0_1.png").unlink()
    os.symlink(tmp_path / "gone.png", folder / "0_1.png")
    assert_fails_cleanly(run_folder(tmp_path, folder), "0_1.png", "does not exist")


def test_fifo_named_like_an_image_is_reported_not_read(tmp_path):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    (folder / "0_0.png").unlink()
    os.mkfifo(folder / "0_0.png")  # reading it would block forever
    assert_fails_cleanly(run_folder(tmp_path, folder), "0_0.png", "not a regular file")


@pytest.mark.slow
def test_unreadable_image_is_an_error_or_skipped_with_a_warning(tmp_path):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    (folder / "1_1.png").write_bytes(b"\x89PNG\r\n\x1a\n garbage")
    assert_fails_cleanly(run_folder(tmp_path, folder), "1_1.png", "not a readable image", "db.on_bad_image=skip")
    proc = run_folder(tmp_path, folder, "db.on_bad_image=skip", "experiment.snapshots=[0]")
    assert proc.returncode == 0, proc.stderr
    assert "1_1.png" in proc.stdout + proc.stderr


@pytest.mark.slow
def test_present_and_missing_cells_are_reported_at_load(tmp_path):
    """``db=original`` with 60 of its 170 images: the load says so."""
    cells = [(x, y) for x, y in grid(10, 17) if y < 6]  # 60 cells
    data = tmp_path / "data"
    make_folder(data / "original", cells)
    proc = run_bionav("db=original", f"data_dir={data}", "homing=mfdid", "experiment.snapshots=[0]",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "60 of 170 grid cells (10 x 17) have an image, 110 missing" in proc.stdout + proc.stderr


@pytest.mark.slow
@pytest.mark.parametrize("bad", ["db.image_size=[100000,20000]", "db.grid_shape=[0,3]", "db.spacing_m=-1"])
def test_bad_db_values_on_a_folder(tmp_path, bad):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    key = bad.split("=")[0]
    assert_fails_cleanly(run_folder(tmp_path, folder, bad), key, "allowed")


def test_metrics_never_hold_nan():
    """The last guard before metrics.json: undefined measures become null, so the file stays strict JSON."""
    from bionav.experiments.runner import json_safe

    safe = json_safe({"aae": float("nan"), "per": [1.0, float("inf")], "x": np.float32(2.5), "n": 3,
                      "arr": np.array([np.nan, 1.0])})
    assert safe == {"aae": None, "per": [1.0, None], "x": 2.5, "n": 3, "arr": [None, 1.0]}
    json.dumps(safe, allow_nan=False)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their mode")
def test_unreadable_file_mode_is_an_error(tmp_path):
    folder = make_folder(tmp_path / "db", grid(2, 2))
    (folder / "1_0.png").chmod(0)
    assert_fails_cleanly(run_folder(tmp_path, folder), "1_0.png", "cannot be read", "db.on_bad_image=skip")


def test_db_help_into_a_closed_pipe_ends_quietly(tmp_path):
    from helpers import run_into_closed_pipe

    proc = run_into_closed_pipe("--help", module="bionav.db", cwd=tmp_path)
    assert proc.returncode == 141, proc.stderr
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr


@pytest.mark.slow
def test_db_export_into_a_folder_another_command_writes_is_refused(tmp_path):
    import json
    import socket

    from helpers import write_tiny_folder

    tiny = write_tiny_folder(tmp_path / "tiny")
    out = tmp_path / "export"
    out.mkdir()
    me = os.getpid()  # a live process holding the folder: this test
    ticks = open(f"/proc/{me}/stat").read().rsplit(")", 1)[-1].split()[19]
    (out / ".bionav.lock").write_text(json.dumps({"pid": me, "host": socket.gethostname(), "start_ticks": ticks}))
    proc = run_bionav("export", "folder", str(out), f"db.path={tiny}", cwd=tmp_path, module="bionav.db")
    assert_fails_cleanly(proc, str(out), "in use by another bionav command", f"pid {me}", code=2, max_seconds=120)
    assert not list(out.glob("*.png"))
    (out / ".bionav.lock").unlink()
    proc = run_bionav("export", "folder", str(out), f"db.path={tiny}", cwd=tmp_path, module="bionav.db")
    assert proc.returncode == 0, proc.stderr
    assert len(list(out.glob("*.png"))) == 9 and not (out / ".bionav.lock").exists()
