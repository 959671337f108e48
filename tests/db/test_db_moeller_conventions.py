"""Möller's database layout (issue 13 item 11): a rendered world written as ``cv_<x>_<y>_bw<c>.pgm`` + ``.db``.

The layout follows the format as Möller's reference min-warping program reads it (WarpingSIMD,
``warpingSIMDTest.C``): file ``cv_<x>_<y>`` is grid cell ``(x - xmin, y - ymin)``, the true home
direction is ``atan2(y_ss - y_cv, x_ss - x_cv)`` in file indices (no mirrored axis), and the image
columns grow with *clockwise* azimuth, column 0 along the grid's +x axis. Loaded through the
``db=moeller1`` preset, min-warping must then point home: its home directions are compared with
the ground truth of the rendered world.
"""

from __future__ import annotations

import numpy as np
import pytest

from bionav.config import compose
from bionav.db.imageio import write_image
from bionav.db.loading import load_database
from bionav.db.synthetic import get_spec, render_world_images
from bionav.evaluation.measures import angular_errors, ideal_home_angles
from bionav.evaluation.pairs import home_vector_matrix

XMIN, YMIN = 3, 1  # file index of grid cell (0, 0): not zero, so a shift or a mirror shows
CELLS_X, CELLS_Y = range(2, 7), range(6, 11)  # 5 x 5 cells of the sim_moeller1 world
WIDTH, HEIGHT = 144, 22


@pytest.fixture(scope="module")
def moeller_folder(tmp_path_factory):
    spec = get_spec("sim_moeller1")
    world = spec.builder(0)
    geometry = spec.geometry(WIDTH, HEIGHT)
    cells = np.array([(i, j) for i in CELLS_X for j in CELLS_Y], dtype=np.int64)
    canonical = render_world_images(world, cells, geometry).mean(axis=-1)  # grey, column j at azimuth +2*pi*j/W
    folder = tmp_path_factory.mktemp("moeller") / "moeller1"
    folder.mkdir()
    x0, y0 = CELLS_X[0], CELLS_Y[0]
    (folder / "moeller1_bw.db").write_text(
        f"{WIDTH} {XMIN} {XMIN + len(CELLS_X) - 1} {YMIN} {YMIN + len(CELLS_Y) - 1} "
        f"{geometry.rad_per_row:.8f} {geometry.horizon_row:g}\n"
    )
    columns = (-np.arange(WIDTH)) % WIDTH  # clockwise on disk: disk column c looks at azimuth -2*pi*c/W
    for (i, j), image in zip(cells, canonical):
        x_file, y_file = XMIN + (i - x0), YMIN + (j - y0)  # same directions as the world grid
        write_image(folder / f"cv_{x_file}_{y_file}_bw0.100000.pgm", image[:, columns])
    return folder, geometry


def test_db_file_gives_grid_and_vertical_geometry(moeller_folder):
    folder, geometry = moeller_folder
    cfg = compose(["db=moeller1", f"db.path={folder}", "db.grid_shape=null"])
    db = load_database(cfg.db, data_dir=folder.parent, cache_dir=folder.parent / "cache")
    assert db.grid_shape == (len(CELLS_X), len(CELLS_Y))
    assert len(db) == 25
    assert db.geometry.horizon_row == pytest.approx(geometry.horizon_row)
    assert db.geometry.rad_per_row == pytest.approx(geometry.rad_per_row, rel=1e-6)
    # file cv_<XMIN+1>_<YMIN+2> is grid cell (1, 2): indices shifted by the .db minimum, not mirrored
    assert db.meta["scheme_index_map"] == f"gx = x - {XMIN}, gy = y - {YMIN}"
    k = db.index_of(1, 2)
    assert db.meta["files"][k] == f"cv_{XMIN + 1}_{YMIN + 2}_bw0.100000.pgm"


def test_min_warping_points_home_on_the_moeller_layout(moeller_folder):
    from bionav.plugins.homing.warping import MinWarping

    folder, _ = moeller_folder
    cfg = compose(["db=moeller1", f"db.path={folder}", "db.grid_shape=null"])
    db = load_database(cfg.db, data_dir=folder.parent, cache_dir=folder.parent / "cache")
    method = MinWarping(MinWarping.Config(image_size=[WIDTH, HEIGHT], n_alpha=72, n_psi=72), geometry=db.geometry)
    snapshots = [db.index_of(2, 2), db.index_of(0, 4), db.index_of(4, 0)]
    hv = home_vector_matrix(method, db, snapshot_index=snapshots, workers=1)
    ae = angular_errors(hv.angles, ideal_home_angles(db.positions[hv.snapshot_index], db.positions))
    aae = float(np.nanmean(ae))
    # the mirrored reading of the old loader turns every home vector about the y axis: AAE near pi/2
    assert aae < 0.35, aae
    assert float(np.nanmedian(ae)) < 0.25
