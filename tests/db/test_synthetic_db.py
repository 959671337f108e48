"""Synthetic stand-in databases: table 3.1, worlds, cache, rotation."""

import numpy as np
import pytest

from bionav.db.synthetic import (
    SYNTHETIC_DATABASES,
    get_spec,
    synthetic_database,
    synthetic_database_names,
)
from bionav.errors import UserError
from bionav.files import cache_key
from bionav.geometry import TWO_PI
from bionav.world.render import render_depth, render_panorama

TABLE_3_1 = {  # name: (grid, spacing, images, mirror)
    "original": ((10, 17), 0.3, 170, "ultra-wide"),
    "arboreal": ((10, 17), 0.3, 170, "ultra-wide"),
    "chairs": ((10, 17), 0.3, 170, "ultra-wide"),
    "day": ((10, 17), 0.3, 170, "ultra-wide"),
    "doorlit": ((10, 17), 0.3, 170, "ultra-wide"),
    "screen": ((10, 17), 0.3, 170, "ultra-wide"),
    "twilight": ((10, 17), 0.3, 170, "ultra-wide"),
    "winlit": ((10, 17), 0.3, 170, "ultra-wide"),
    "hall1": ((10, 20), 0.5, 170, "ultra-wide"),
    "hall2": ((10, 20), 0.5, 170, "ultra-wide"),
    "moeller1": ((11, 22), 0.1, 242, "ultra-wide"),
    "roeben1": ((11, 36), 0.1, 396, "ultra-wide"),
    "uni": ((10, 17), 1.0, 170, "normal-view"),
}


def _inside_any_solid(scene, p):
    """True if point p lies inside a (non-shell) primitive of the scene."""
    x, y, z = p
    for b in scene.boxes:
        cx, cy, cz, hx, hy, hz, cs, sn, inside = b[:9]
        if inside:
            continue
        lx = cs * (x - cx) + sn * (y - cy)
        ly = -sn * (x - cx) + cs * (y - cy)
        if abs(lx) <= hx and abs(ly) <= hy and abs(z - cz) <= hz:
            return True
    for f in scene.frusta:
        cx, cy, z0, z1, r0, r1 = f[:6]
        if z0 <= z <= z1 and np.hypot(x - cx, y - cy) <= r0 + (r1 - r0) * (z - z0) / (z1 - z0):
            return True
    for e in scene.ellipsoids:
        q = (np.array(p) - np.array(e[:3])) / np.array(e[3:6])
        if q @ q <= 1:
            return True
    return False


def test_table_matches_thesis_table_3_1():
    assert sorted(SYNTHETIC_DATABASES) == sorted("sim_" + k for k in TABLE_3_1)
    for name, (grid, spacing, n, mirror) in TABLE_3_1.items():
        spec = get_spec("sim_" + name)
        assert spec.grid_shape == grid and spec.spacing_m == spacing
        assert spec.n_images == n and spec.mirror == mirror


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SYNTHETIC_DATABASES))
def test_world_grid_cells_and_free_cameras(name):
    spec = get_spec(name)
    w = spec.builder(0)
    assert w.grid_shape == spec.grid_shape
    assert w.spacing == spec.spacing_m
    assert w.cells.shape == spec.grid_shape and w.cells.sum() == spec.n_images
    for i, j in np.argwhere(w.cells):
        assert not _inside_any_solid(w.scene, w.cell_position(i, j)), (name, i, j)


def test_hall_misses_the_cells_under_its_kiosk():
    w = get_spec("sim_hall1").builder(0)
    missing = np.argwhere(~w.cells)
    assert len(missing) == 30
    # every cell whose camera would stand inside an obstacle is among the missing ones
    inside = [tuple(c) for c in np.argwhere(np.ones(w.grid_shape, bool))
              if _inside_any_solid(w.scene, w.cell_position(*c))]
    assert inside and set(inside) <= set(map(tuple, missing))
    w2 = get_spec("sim_hall2").builder(0)
    assert not np.array_equal(w.cells, w2.cells) or w.grid_origin != w2.grid_origin


def test_lab_row_16_lies_under_the_table():
    w = get_spec("sim_original").builder(0)
    from bionav.geometry import PanoramaGeometry

    geo = PanoramaGeometry.square_pixels(64, 16)
    for j, covered in ((16, True), (14, False)):
        depth, _, _ = render_depth(w.scene, position=w.cell_position(4, j), geometry=geo)
        top = depth[0]  # highest row: a table top 0.1 m above the camera is near
        assert (np.median(top) < 1.0) == covered


def test_variants_share_the_geometry_and_change_what_their_names_say():
    from bionav.geometry import PanoramaGeometry

    geo = PanoramaGeometry.square_pixels(96, 16)
    worlds = {n: get_spec(n).builder(0) for n in ("sim_original", "sim_doorlit", "sim_winlit", "sim_arboreal")}
    pos = worlds["sim_original"].cell_position(2, 3)
    d0, _, _ = render_depth(worlds["sim_original"].scene, position=pos, geometry=geo)
    imgs = {n: render_panorama(w.scene, position=pos, geometry=geo) for n, w in worlds.items()}
    for n in ("sim_doorlit", "sim_winlit"):
        d, _, _ = render_depth(worlds[n].scene, position=pos, geometry=geo)
        np.testing.assert_array_equal(d, d0)
        assert imgs[n].mean() < imgs["sim_original"].mean()
    d_plant, _, _ = render_depth(worlds["sim_arboreal"].scene, position=pos, geometry=geo)
    changed = d_plant != d0
    assert 0 < changed.mean() < 0.2  # the plant occludes part of the view, nothing else moved
    assert np.all(d_plant[changed] < d0[changed])


def test_same_seed_same_world_other_seed_other_world():
    from bionav.geometry import PanoramaGeometry

    geo = PanoramaGeometry.square_pixels(64, 12)
    a = get_spec("sim_original").builder(0)
    b = get_spec("sim_original").builder(0)
    c = get_spec("sim_original").builder(1)
    assert a.scene.compile().digest() == b.scene.compile().digest()
    assert a.scene.compile().digest() != c.scene.compile().digest()
    ia = render_panorama(a.scene, position=a.cell_position(1, 1), geometry=geo)
    ib = render_panorama(b.scene, position=b.cell_position(1, 1), geometry=geo)
    np.testing.assert_array_equal(ia, ib)


def test_unknown_name_lists_the_valid_ones(tmp_path):
    with pytest.raises(UserError) as e:
        synthetic_database("sim_nowhere", cache_dir=tmp_path)
    for n in synthetic_database_names():
        assert n in str(e.value)


def test_cache_round_trip_and_key(tmp_path):
    kw = dict(image_size=(40, 6), cache_dir=tmp_path)
    db = synthetic_database("sim_original", **kw)
    assert db.images.shape == (170, 6, 40) and db.images.dtype == np.float32
    assert not db.meta["from_cache"]
    assert db.grid_shape == (10, 17) and db.spacing_m == 0.3
    assert np.all(db.headings == 0)
    # 8-bit quantisation
    np.testing.assert_allclose(db.images * 255, np.round(db.images * 255), atol=1e-4)
    again = synthetic_database("sim_original", **kw)
    assert again.meta["from_cache"]
    np.testing.assert_array_equal(again.images, db.images)
    np.testing.assert_array_equal(again.positions, db.positions)
    assert len(list(tmp_path.glob("*.npz"))) == 1
    other = synthetic_database("sim_original", noise=0.0, **kw)
    assert not other.meta["from_cache"] and len(list(tmp_path.glob("*.npz"))) == 2
    assert not np.array_equal(other.images, db.images)
    assert np.abs(other.images - db.images).mean() < 0.02
    assert cache_key({"a": 1, "b": 2}) == cache_key({"b": 2, "a": 1}) != cache_key({"a": 1, "b": 3})


def test_uni_ideal_cache_key_follows_the_sky(tmp_path, monkeypatch):
    """The campus' sky is not in the compiled scene's digest: its description (World.info["sky"]) keys the renders."""
    from bionav.world.worlds import outdoor

    kw = dict(image_size=(24, 4), cache_dir=tmp_path)
    ideal = synthetic_database("sim_uni", **kw)
    assert synthetic_database("sim_uni", **kw).meta["from_cache"]
    monkeypatch.setattr(outdoor, "CLOUD_RADIANCE", 2.0)  # brighter clouds in the sky, same geometry
    brighter = synthetic_database("sim_uni", **kw)
    assert not brighter.meta["from_cache"] and brighter.meta["cache_file"] != ideal.meta["cache_file"]
    world = get_spec("sim_uni").builder(0)
    k = int(np.flatnonzero((ideal.positions == [4, 8]).all(axis=1))[0])
    sky = np.isinf(render_depth(world.scene, position=world.cell_position(4, 8),
                                geometry=get_spec("sim_uni").geometry(24, 4))[0])
    assert sky.any() and np.all(brighter.images[k][sky] >= ideal.images[k][sky])
    assert np.any(brighter.images[k][sky] > ideal.images[k][sky])  # the clouds in view are brighter
    np.testing.assert_array_equal(brighter.images[k][~sky], ideal.images[k][~sky])  # nothing else changed


def test_random_rotation_rolls_and_records_headings(tmp_path):
    kw = dict(image_size=(40, 6), cache_dir=tmp_path, noise=0.0)
    db = synthetic_database("sim_original", **kw)
    rot = synthetic_database("sim_original", rotate_current=True, rotation_seed=3, **kw)
    assert np.any(rot.headings != 0)
    for i in range(0, 170, 17):
        k = int(round(rot.headings[i] / TWO_PI * 40)) % 40
        np.testing.assert_array_equal(rot.images[i], np.roll(db.images[i], -k, axis=1))
    rot2 = synthetic_database("sim_original", rotate_current=True, rotation_seed=3, **kw)
    np.testing.assert_array_equal(rot2.headings, rot.headings)


def test_hall_database_positions(tmp_path):
    db = synthetic_database("sim_hall1", image_size=(32, 6), cache_dir=tmp_path)
    assert len(db) == 170 and db.grid_shape == (10, 20)
    lut = db.cell_index_map()
    assert (lut >= 0).sum() == 170
    assert len({tuple(p) for p in db.positions}) == 170


def test_uni_uses_the_normal_view_field(tmp_path):
    spec = get_spec("sim_uni")
    g = spec.geometry(561, 81)
    up = g.row_elevations()[0]
    down = g.row_elevations()[-1]
    assert np.deg2rad(10) <= up <= np.deg2rad(26)
    assert down < -np.deg2rad(26)
    u = get_spec("sim_original").geometry(1122, 162)
    assert np.deg2rad(25) < u.row_elevations()[0] < np.deg2rad(27)


def test_apartment_free_area_is_free():
    from bionav.world.worlds.apartment import build_apartment

    w = build_apartment(0)
    x0, y0, x1, y1 = w.free_area
    assert x1 - x0 >= 2.4 and y1 - y0 >= 4.4
    for x in np.linspace(x0, x1, 13):
        for y in np.linspace(y0, y1, 21):
            for z in (0.05, 0.3, 0.6):
                assert not _inside_any_solid(w.scene, (x, y, z))


def test_campus_renders_five_bands_with_caller_albedos_and_sky():
    from bionav.light.materials import band_albedos
    from bionav.world.worlds.outdoor import build_campus

    bands = ("UV", "B", "G", "R", "IR")
    albedos = {k: list(v) for k, v in band_albedos(bands).items()}
    albedos["foliage"] = [0.0, 0.0, 0.0, 0.0, 0.9]  # leaves visible in IR only
    seen = []

    def sky(d):
        seen.append(len(d))
        return np.tile([0.5, 0.4, 0.3, 0.2, 0.1], (len(d), 1))

    w = build_campus(0, channels=bands, albedos=albedos, sky=sky)
    geo = get_spec("sim_uni").geometry(96, 14)
    img = render_panorama(w.scene, position=w.cell_position(4, 8), geometry=geo, clip=False)
    assert img.shape == (14, 96, 5) and seen and sum(seen) > 0
    depth, kind, idx = render_depth(w.scene, position=w.cell_position(4, 8), geometry=geo)
    sky_px = np.isinf(depth)
    np.testing.assert_allclose(img[sky_px] / w.scene.exposure, np.tile([0.5, 0.4, 0.3, 0.2, 0.1], (sky_px.sum(), 1)),
                               rtol=1e-6)
    # tree crowns (ellipsoids with the foliage albedo) are black in UV..R and bright in IR
    crown = kind == 2
    if crown.any():
        assert np.all(img[crown][:, :4] < 0.2 * img[crown][:, 4].max() + 1e-6)
    with pytest.raises(ValueError):
        build_campus(0, channels=bands, albedos={"concrete": [0.1] * 5})


def test_concurrent_workers_share_the_cache(tmp_path):
    from concurrent.futures import ThreadPoolExecutor

    kw = dict(image_size=(24, 4), cache_dir=tmp_path)
    with ThreadPoolExecutor(2) as pool:
        a, b = pool.map(lambda _: synthetic_database("sim_winlit", **kw), range(2))
    np.testing.assert_array_equal(a.images, b.images)
    assert len(list(tmp_path.glob("*.npz"))) == 1
    assert not list(tmp_path.glob("*.tmp"))
    assert synthetic_database("sim_winlit", **kw).meta["from_cache"]
