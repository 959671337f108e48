"""The stand-in worlds are hard for their real counterparts' physical reasons (issue 18, docs/databases.md)."""

from __future__ import annotations

import numpy as np
import pytest

from bionav.db.synthetic import get_spec
from bionav.geometry import PanoramaGeometry
from bionav.world.render import render_depth, render_panorama

GEO = PanoramaGeometry.square_pixels(180, 26)  # 2 degrees per pixel, +-26 degrees
AZ = 2 * np.pi * np.arange(GEO.width) / GEO.width  # world azimuth of each column (heading 0)


def _radiance(name: str, cell) -> np.ndarray:
    w = get_spec(name).builder(0)
    return render_panorama(w.scene, position=w.cell_position(*cell), geometry=GEO, exposure=1.0, clip=False)[..., 0]


def _within(az: np.ndarray, centre: float, half: float) -> np.ndarray:
    return np.abs(np.angle(np.exp(1j * (az - centre)))) < half


@pytest.mark.parametrize("cell", [(2, 3), (5, 8), (8, 14)])
def test_doorlit_and_winlit_change_shading_not_just_brightness(cell):
    # the door is in the west wall (looking along -x, azimuth pi), the windows in the east wall (azimuth 0)
    ratio = np.log((_radiance("sim_doorlit", cell) + 1e-4) / (_radiance("sim_winlit", cell) + 1e-4))
    west, east = _within(AZ, np.pi, np.pi / 4), _within(AZ, 0.0, np.pi / 4)
    # the side under the band that is on is brighter, by more than a factor of two relative to the other side
    assert np.median(ratio[:, west]) - np.median(ratio[:, east]) > np.log(2.0)
    # a change of brightness alone would make the log ratio uniform; shading and shadows spread it
    assert np.percentile(ratio, 90) - np.percentile(ratio, 10) > 1.0


def _spread_cells(world, n: int = 6) -> list[tuple[int, int]]:
    """``n`` existing cells evenly spread over the database's image order."""
    cells = np.argwhere(world.cells)
    return [tuple(map(int, c)) for c in cells[np.linspace(0, len(cells) - 1, n).round().astype(int)]]


@pytest.mark.slow
def test_the_hall_at_night_is_darker_and_sparser_than_the_lab():
    def light(name):
        w = get_spec(name).builder(0)
        x = np.concatenate([_radiance(name, c).ravel() for c in _spread_cells(w)])
        return x, float(np.median(x)) * w.scene.exposure * w.light_level  # the light the camera gets

    (hall, hall_cam), (lab, lab_cam) = light("sim_hall1"), light("sim_original")
    assert np.median(hall) < 0.5 * np.median(lab)
    # at the camera the night hall gives less than a tenth of the lit lab's light (World.light_level)
    assert hall_cam < 0.1 * lab_cam
    # large dark areas between the few lit patches: many pixels below a tenth of the bright end
    dark = lambda x: float(np.mean(x < 0.1 * np.percentile(x, 95)))  # noqa: E731
    assert dark(hall) > 0.02 and dark(hall) > 10 * dark(lab)


def test_living_room_lanes_pass_close_to_furniture():
    def near(name, cell, metres):
        w = get_spec(name).builder(0)
        depth, _, _ = render_depth(w.scene, position=w.cell_position(*cell), geometry=GEO)
        return depth, float(np.mean(depth < metres))

    # roeben1: the lane starts between kitchen counters and dining table and ends in the open living room
    _, start = near("sim_roeben1", (5, 0), 1.0)
    _, end = near("sim_roeben1", (5, 35), 1.0)
    assert start > 0.4 and end < 0.25
    # moeller1: furniture within 0.4 m of the outermost cells of both long sides
    for cell in [(0, 10), (10, 10)]:
        depth, _ = near("sim_moeller1", cell, 1.0)
        assert depth[GEO.height // 2:].min() < 0.4


def test_uni_trees_are_distant_and_the_grid_lies_in_the_buildings_shadow():
    from bionav.world.worlds.outdoor import TREE_CLEARANCE

    w = get_spec("sim_uni").builder(0)
    kinds = [m.kind for m in w.scene.materials]
    (nx, ny), s = w.grid_shape, w.spacing
    x0, y0 = w.grid_origin
    x1, y1 = x0 + s * (nx - 1), y0 + s * (ny - 1)
    trunks = [f for f in w.scene.frusta if kinds[f[7]] == "bark"]
    assert len(trunks) >= 10
    for f in trunks:
        dx = max(x0 - f[0], 0.0, f[0] - x1)
        dy = max(y0 - f[1], 0.0, f[1] - y1)
        assert max(dx, dy) >= TREE_CLEARANCE
    # the sun stands behind the main building: the paving seen steeply below the camera gets no direct
    # sunlight anywhere on the grid (sky light only: about 1.2 / (1.2 + 2.2 sin 35 deg) = 0.49 of full light)
    down = PanoramaGeometry(width=16, height=3, horizon_row=-4.0, rad_per_row=0.2)  # rows 46-69 deg down
    for cell in [(0, 0), (9, 16), (4, 8), (0, 16), (9, 0)]:
        kw = dict(position=w.cell_position(*cell), geometry=down, exposure=1.0, clip=False)
        ratio = render_panorama(w.scene, **kw).mean() / render_panorama(w.scene, shadows=False, **kw).mean()
        assert ratio < 0.6, cell
