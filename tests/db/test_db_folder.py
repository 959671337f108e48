"""Folder loaders: naming schemes, conventions, validation (tiny fixture folders made here)."""

from __future__ import annotations

import logging
from pathlib import Path

import cv2
import numpy as np
import pytest

from bionav.db.config import DatabaseConfig, UnfoldConfig
from bionav.db.conventions import from_canonical, to_canonical
from bionav.db.loading import load_database, rotate_views
from bionav.errors import UserError

H, W = 6, 16


def cell_image(x: int, y: int, *, height: int = H, width: int = W) -> np.ndarray:
    """An 8-bit image that encodes its cell: a column ramp plus 20*x + 3*y."""
    base = (np.arange(width)[None, :] * 5 + np.arange(height)[:, None] * 2) % 50
    return (base + 20 * x + 3 * y).astype(np.uint8)


def write(path: Path, img: np.ndarray) -> Path:
    assert cv2.imwrite(str(path), img)
    return path


def load(path: Path, **kw) -> "object":
    cfg = DatabaseConfig(name=kw.pop("name", "fixture"), source="folder", path=str(path), **kw)
    return load_database(cfg, data_dir=path.parent, cache_dir=path.parent / "cache")


def canonical_of_disk(img: np.ndarray) -> np.ndarray:
    """Bielefeld disk -> canonical by hand: canonical[:, j] = disk[:, (-j) mod W]."""
    w = img.shape[-1]
    return img[..., (-np.arange(w)) % w]


# --------------------------------------------------------------------------- Vardy naming


def test_vardy_missing_cells_formats_and_ignored_files(tmp_path, caplog):
    cells = [(0, 0), (1, 0), (2, 0), (0, 1), (2, 1), (0, 3), (2, 3)]  # (1,1), (*,2), (1,3) missing
    exts = ["png", "pgm", "bmp", "png", "pgm", "png", "bmp"]
    for (x, y), ext in zip(cells, exts):
        write(tmp_path / f"{x}_{y}.{ext}", cell_image(x, y))
    (tmp_path / "notes.txt").write_text("not an image")
    write(tmp_path / "snapshot.png", cell_image(9, 9))  # image that does not follow the naming
    with caplog.at_level(logging.WARNING):
        db = load(tmp_path)
    ignored = [r for r in caplog.records if "ignoring" in r.getMessage()]
    assert len(ignored) == 1 and "notes.txt" in ignored[0].getMessage() and "snapshot.png" in ignored[0].getMessage()
    assert db.grid_shape == (3, 4)
    assert sorted(map(tuple, db.positions.tolist())) == sorted(cells)
    assert db.images.dtype == np.float32 and db.images.shape == (7, H, W)
    for i, (x, y) in enumerate(db.positions):
        expected = canonical_of_disk(cell_image(x, y)).astype(np.float32) / np.float32(255)
        np.testing.assert_array_equal(db.images[i], expected)
    assert db.index_of(1, 1) is None and db.index_of(2, 3) is not None
    assert db.geometry.horizon_row == (H - 1) / 2 and db.geometry.rad_per_row == pytest.approx(2 * np.pi / W)
    assert db.meta["naming"] == "vardy"


def test_16bit_and_colour_images_become_grey_floats(tmp_path):
    rng = np.random.default_rng(1)
    img16 = rng.integers(0, 65536, size=(H, W), dtype=np.uint16)
    colour = rng.integers(0, 256, size=(H, W, 3), dtype=np.uint8)
    write(tmp_path / "0_0.png", img16)
    write(tmp_path / "1_0.png", colour)
    db = load(tmp_path, azimuth="counterclockwise")
    np.testing.assert_allclose(db.images[db.index_of(0, 0)], img16 / 65535.0, atol=1e-7)
    grey = cv2.cvtColor(colour, cv2.COLOR_BGR2GRAY).astype(np.float32) / 255
    np.testing.assert_array_equal(db.images[db.index_of(1, 0)], grey)


def test_pgm_maxval_is_respected(tmp_path):
    data = np.arange(H * W, dtype=np.uint16).reshape(H, W) % 4096
    (tmp_path / "0_0.pgm").write_bytes(f"P5\n{W} {H}\n4095\n".encode() + data.astype(">u2").tobytes())
    db = load(tmp_path, azimuth="counterclockwise")
    np.testing.assert_allclose(db.images[0], data / 4095.0, rtol=1e-6)


# --------------------------------------------------------------------------- conventions


@pytest.mark.parametrize("azimuth,c0", [("clockwise", 0), ("clockwise", 5), ("counterclockwise", 11)])
def test_bright_column_comes_back_at_its_azimuth(tmp_path, azimuth, c0):
    width, k = 36, 7  # the bright object is at azimuth 2*pi*7/36 = 70 deg CCW from grid +x
    s = -1 if azimuth == "clockwise" else 1
    disk = np.full((5, width), 40, np.uint8)
    disk[:, (c0 + s * k) % width] = 250  # column c looks at azimuth s*2*pi*(c - c0)/W
    write(tmp_path / "0_0.png", disk)
    db = load(tmp_path, azimuth=azimuth, x_axis_column=c0)
    assert int(np.argmax(db.images[0].mean(axis=0))) == k
    az = db.geometry.column_azimuths()[np.argmax(db.images[0].mean(axis=0))]
    assert az == pytest.approx(np.deg2rad(70.0))


def test_fractional_x_axis_column():
    width, c0 = 64, 10.5
    c = np.arange(width)
    disk = np.cos(2 * np.pi * (c - c0) / width)[None, :].repeat(3, 0)  # clockwise: theta = -2pi(c-c0)/W
    canon = to_canonical(disk, azimuth="clockwise", x_axis_column=c0)
    np.testing.assert_allclose(canon[0], np.cos(2 * np.pi * c / width), atol=(2 * np.pi / width) ** 2 / 8 + 1e-9)
    back = from_canonical(to_canonical(disk, azimuth="cw", x_axis_column=3), azimuth="cw", x_axis_column=3)
    np.testing.assert_array_equal(back, disk)


def test_unknown_azimuth_is_a_user_error():
    with pytest.raises(UserError, match="db.azimuth"):
        to_canonical(np.zeros((2, 4)), azimuth="sideways")


def test_rotate_views_records_headings(tmp_path):
    width, k = 24, 5
    for x in range(4):
        disk = np.full((3, width), 30, np.uint8)
        disk[:, (-k) % width] = 240
        write(tmp_path / f"{x}_0.png", disk)
    db = load(tmp_path, rotate_current=True, rotation_seed=3)
    assert np.any(db.headings != 0)
    for img, heading in zip(db.images, db.headings):
        j = int(np.argmax(img.mean(axis=0)))
        # column j looks at grid azimuth heading + 2*pi*j/W; the bright object is at 2*pi*k/W
        assert np.isclose(np.cos(heading + 2 * np.pi * j / width - 2 * np.pi * k / width), 1.0)
    same = rotate_views(load(tmp_path), seed=3)
    np.testing.assert_array_equal(same.images, db.images)


# --------------------------------------------------------------------------- Möller naming


def write_moeller(folder: Path, *, xmin=1, xmax=4, ymin=2, ymax=4, vert_res="0.0218", horizon="2.5",
                  cutoff="0.100000", skip=()):
    (folder / "moeller1.db").write_text(f"{W} {xmin} {xmax} {ymin} {ymax} {vert_res} {horizon}\n")
    for x in range(xmin, xmax + 1):
        for y in range(ymin, ymax + 1):
            if (x, y) not in skip:
                write(folder / f"cv_{x}_{y}_bw{cutoff}.pgm", cell_image(x, y))


def test_moeller_indices_shift_by_min_and_db_metadata(tmp_path):
    write_moeller(tmp_path, skip={(2, 3)})
    db = load(tmp_path, naming="auto")
    assert db.meta["naming"] == "moeller"
    assert db.grid_shape == (4, 3)  # xmax - xmin + 1, ymax - ymin + 1
    assert len(db) == 11
    for i, (gx, gy) in enumerate(db.positions):
        x_file, y_file = gx + 1, gy + 2  # gx = x - xmin, gy = y - ymin (issue 13 item 11: no mirroring)
        expected = canonical_of_disk(cell_image(x_file, y_file)).astype(np.float32) / 255
        np.testing.assert_array_equal(db.images[i], expected)
    assert db.index_of(2 - 1, 3 - 2) is None  # the missing file cv_2_3 is grid cell (1, 1)
    assert db.geometry.horizon_row == 2.5 and db.geometry.rad_per_row == pytest.approx(0.0218)


def test_moeller_vert_res_in_degrees_and_overrides(tmp_path):
    write_moeller(tmp_path, vert_res="1.25", horizon="3")
    db = load(tmp_path)
    assert db.geometry.rad_per_row == pytest.approx(np.deg2rad(1.25))
    db = load(tmp_path, horizon_row=1.0, rad_per_row=0.01)
    assert (db.geometry.horizon_row, db.geometry.rad_per_row) == (1.0, 0.01)


def test_moeller_several_cutoffs_need_a_choice(tmp_path):
    write_moeller(tmp_path, cutoff="0.1")
    write(tmp_path / "cv_1_2_bw1.0.pgm", cell_image(0, 0))
    with pytest.raises(UserError, match=r"db.extra.bw_cutoff"):
        load(tmp_path)
    db = load(tmp_path, extra={"bw_cutoff": 1.0})
    assert len(db) == 1 and tuple(db.positions[0]) == (0, 0)  # cv_1_2 with xmin=1, ymin=2


def test_moeller_bad_db_file(tmp_path):
    write_moeller(tmp_path)
    (tmp_path / "moeller1.db").write_text("this is not a header\n")
    with pytest.raises(UserError, match="moeller1.db"):
        load(tmp_path)


# --------------------------------------------------------------------------- CSV naming


def test_csv_with_file_names(tmp_path):
    (tmp_path / "a.png").write_bytes(cv2.imencode(".png", cell_image(0, 5))[1].tobytes())
    write(tmp_path / "b.jpg", np.full((H, W), 128, np.uint8))
    (tmp_path / "positions.csv").write_text("x,y,filename\n0,5,a.png\n3,1,b.jpg\n")
    db = load(tmp_path)
    assert db.meta["naming"] == "csv" and db.grid_shape == (4, 6)
    np.testing.assert_array_equal(db.images[db.index_of(0, 5)],
                                  canonical_of_disk(cell_image(0, 5)).astype(np.float32) / 255)
    assert db.index_of(3, 1) is not None


def test_csv_without_file_names_uses_natural_order(tmp_path):
    for i in (1, 2, 10):
        write(tmp_path / f"img{i}.png", cell_image(i, 0))
    (tmp_path / "pos.csv").write_text("0,0\n1,0\n2,0\n")
    db = load(tmp_path)
    # img1 -> (0,0), img2 -> (1,0), img10 -> (2,0): natural, not lexical, order
    for gx, i in ((0, 1), (1, 2), (2, 10)):
        np.testing.assert_array_equal(db.images[db.index_of(gx, 0)],
                                      canonical_of_disk(cell_image(i, 0)).astype(np.float32) / 255)


def test_csv_bad_row_is_named(tmp_path):
    write(tmp_path / "a.png", cell_image(0, 0))
    (tmp_path / "positions.csv").write_text("x,y,filename\n0,zero,a.png\n")
    with pytest.raises(UserError, match=r"positions.csv row 2"):
        load(tmp_path)


# --------------------------------------------------------------------------- validation


def good_folder(folder: Path, n: int = 3) -> None:
    for x in range(n):
        write(folder / f"{x}_0.png", cell_image(x, 0))


def test_truncated_png_is_named(tmp_path):
    good_folder(tmp_path)
    data = (tmp_path / "1_0.png").read_bytes()
    (tmp_path / "1_0.png").write_bytes(data[: len(data) // 2])
    with pytest.raises(UserError, match=r"1_0\.png.*truncated.*on_bad_image=skip"):
        load(tmp_path)


def test_truncated_jpeg_is_named(tmp_path):
    good_folder(tmp_path)
    data = cv2.imencode(".jpg", cell_image(5, 0))[1].tobytes()
    (tmp_path / "5_0.jpg").write_bytes(data[:-40])
    with pytest.raises(UserError, match=r"5_0\.jpg.*truncated"):
        load(tmp_path)


def test_matching_file_that_is_not_an_image(tmp_path):
    good_folder(tmp_path)
    (tmp_path / "2_1.png").write_text("hello, I am text")
    with pytest.raises(UserError, match=r"2_1\.png.*not a readable image"):
        load(tmp_path)


def test_mixed_sizes_name_the_odd_file(tmp_path):
    good_folder(tmp_path)
    write(tmp_path / "0_1.png", cell_image(0, 1, height=H + 2))
    with pytest.raises(UserError, match=r"0_1\.png is 16 x 8 pixels.*16 x 6"):
        load(tmp_path)


def test_duplicate_cell(tmp_path):
    good_folder(tmp_path)
    write(tmp_path / "1_0.pgm", cell_image(1, 0))
    with pytest.raises(UserError, match=r"\(1, 0\).*1_0\.p.*1_0\.p"):
        load(tmp_path)


def test_cell_outside_declared_grid(tmp_path):
    good_folder(tmp_path)
    with pytest.raises(UserError, match=r"2_0\.png.*outside the declared 2 x 1 grid"):
        load(tmp_path, grid_shape=[2, 1])


def test_skip_turns_bad_images_into_warnings(tmp_path, caplog):
    good_folder(tmp_path, n=4)
    data = (tmp_path / "1_0.png").read_bytes()
    (tmp_path / "1_0.png").write_bytes(data[:-20])
    write(tmp_path / "2_0.png", cell_image(2, 0, width=W + 4))
    write(tmp_path / "0_5.png", cell_image(0, 5))
    with caplog.at_level(logging.WARNING):
        db = load(tmp_path, grid_shape=[4, 2], on_bad_image="skip")
    assert sorted(map(tuple, db.positions.tolist())) == [(0, 0), (3, 0)]
    assert db.grid_shape == (4, 2)
    warned = " ".join(r.getMessage() for r in caplog.records)
    for name in ("1_0.png", "2_0.png", "0_5.png"):
        assert name in warned
    assert sorted(db.meta["skipped"]) == ["0_5.png", "1_0.png", "2_0.png"]


def test_empty_folder_and_folder_without_images(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(UserError, match="it is empty"):
        load(empty)
    (empty / "readme.pdf").write_text("x")
    with pytest.raises(UserError, match=r"readme\.pdf.*<x>_<y>\.png"):
        load(empty)


def test_missing_database_folder_message(tmp_path):
    cfg = DatabaseConfig(name="hall1", source="folder", path=None)
    with pytest.raises(UserError) as err:
        load_database(cfg, data_dir=tmp_path / "nowhere", cache_dir=tmp_path)
    msg = str(err.value)
    assert str((tmp_path / "nowhere" / "hall1").resolve()) in msg
    assert "BIONAV_DATA" in msg and "data_dir=" in msg and "db=sim_hall1" in msg


def test_image_size_resizes_and_updates_geometry(tmp_path):
    good_folder(tmp_path)
    cfg = DatabaseConfig(name="f", source="folder", path=str(tmp_path), image_size=[8, 3], horizon_row=2.5,
                         rad_per_row=0.1)
    db = load_database(cfg, data_dir=tmp_path, cache_dir=tmp_path)
    assert db.images.shape == (3, 3, 8)
    assert db.geometry.width == 8 and db.geometry.height == 3
    # the horizon keeps its elevation: row 2.5 of 6 rows -> row (2.5 + 0.5) * 3/6 - 0.5 = 1.0 of 3
    assert db.geometry.horizon_row == pytest.approx(1.0) and db.geometry.rad_per_row == pytest.approx(0.2)


# --------------------------------------------------------------------------- raw frames


def test_unfold_and_raw_access(tmp_path):
    size = 41
    yy, xx = np.mgrid[0:size, 0:size]
    angle = np.arctan2(yy - 20, xx - 20) % (2 * np.pi)
    raw = np.where(np.abs(np.angle(np.exp(1j * (angle - np.pi / 2)))) < 0.2, 250, 30).astype(np.uint8)
    raw[(xx - 20) ** 2 + (yy - 20) ** 2 < 16] = 0
    for x in range(2):
        write(tmp_path / f"{x}_0.png", raw)
    unfold = UnfoldConfig(enabled=True, center=[20.0, 20.0], inner_radius=6.0, outer_radius=18.0, size=[32, 5])
    db = load(tmp_path, unfold=unfold, azimuth="counterclockwise")
    assert db.images.shape == (2, 5, 32)
    # the bright ray at polar angle pi/2 (pixel axes) lands in column 32 * (pi/2) / (2 pi) = 8
    assert int(np.argmax(db.images[0].mean(axis=0))) == 8
    np.testing.assert_array_equal(db.raw(1), raw.astype(np.float32) / 255)
    sub = db.subset([1])
    np.testing.assert_array_equal(sub.raw(0), raw.astype(np.float32) / 255)
