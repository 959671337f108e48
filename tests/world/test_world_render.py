"""The panorama renderer against closed forms and its NumPy reference."""

import numpy as np
import pytest

from bionav.geometry import TWO_PI, PanoramaGeometry
from bionav.world.intersect import trace_depth_reference
from bionav.world.lights import Ambient, DirectionalLight, PointLight
from bionav.world.render import ray_grid, render_depth, render_panorama
from bionav.world.scene import Scene


def _directions(geometry, heading=0.0):
    az, el = ray_grid(geometry, heading)
    ce = np.cos(el)[:, None]
    return np.stack([ce * np.cos(az)[None, :], ce * np.sin(az)[None, :],
                     np.broadcast_to(np.sin(el)[:, None], (el.size, az.size))], axis=-1)


def test_single_wall_edges_and_depth_match_the_closed_form():
    # a wall face at x = 2 spanning y in [-1, 1], z in [0, 1.5]; camera at z = 0.5
    s = Scene()
    s.box((2.0, -1.0, 0.0), (2.2, 1.0, 1.5), s.material())
    geo = PanoramaGeometry.square_pixels(360, 90)
    depth, kind, _ = render_depth(s, position=(0.0, 0.0, 0.5), geometry=geo)
    d = _directions(geo)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = 2.0 / d[..., 0]
        y = t * d[..., 1]
        z = 0.5 + t * d[..., 2]
    expected = (d[..., 0] > 0) & (np.abs(y) <= 1.0) & (z >= 0.0) & (z <= 1.5)
    margin = (np.abs(np.abs(y) - 1.0) < 1e-9) | (np.abs(z) < 1e-9) | (np.abs(z - 1.5) < 1e-9)
    hit = kind >= 0
    assert np.array_equal(hit[~margin], expected[~margin])
    np.testing.assert_allclose(depth[expected], t[expected], rtol=1e-9)
    # the top edge straight ahead lies at elevation atan(1/2), the side edges at azimuth +-atan(1/2)
    col0 = hit[:, 0]
    top_row = np.flatnonzero(col0)[0]
    el = geo.row_elevations()
    assert el[top_row] <= np.arctan2(1.0, 2.0) < el[top_row - 1]
    horizon = int(round(geo.horizon_row))
    cols = np.flatnonzero(hit[horizon])
    az = geo.column_azimuths()
    left = az[cols[cols < 180]].max()
    assert left <= np.arctan2(1.0, 2.0) < left + geo.rad_per_column


def test_pillar_shifts_by_the_predicted_angle_between_two_positions():
    s = Scene()
    s.cylinder((3.0, 0.0), 0.0, 2.0, 0.05, material=s.material())
    geo = PanoramaGeometry.square_pixels(720, 60)
    h = int(round(geo.horizon_row))
    for pos in ((0.0, 0.0), (0.0, 1.0), (1.5, -2.0)):
        _, kind, _ = render_depth(s, position=(*pos, 0.6), geometry=geo)
        cols = np.flatnonzero(kind[h] >= 0)
        az = geo.column_azimuths()[cols]
        centre = np.angle(np.exp(1j * az).mean())
        predicted = np.arctan2(0.0 - pos[1], 3.0 - pos[0])
        assert abs(np.angle(np.exp(1j * (centre - predicted)))) < geo.rad_per_column


def _random_scene(rng):
    s = Scene()
    m = s.material()
    for _ in range(6):
        lo = rng.uniform(-4, 4, 3)
        lo[2] = rng.uniform(0, 1)
        s.box(lo, lo + rng.uniform(0.1, 1.5, 3), m, yaw=rng.uniform(-np.pi, np.pi))
    for _ in range(4):
        z0 = rng.uniform(0, 1)
        r0, r1 = rng.uniform(0.05, 0.6, 2)
        if rng.random() < 0.3:
            r1 = 0.0
        s.frustum(rng.uniform(-4, 4, 2), z0, z0 + rng.uniform(0.2, 2.0), r0, r1, material=m)
    for _ in range(3):
        s.ellipsoid(rng.uniform(-4, 4, 3) * [1, 1, 0.3] + [0, 0, 1], rng.uniform(0.1, 0.8, 3), material=m)
    s.box((-6, -6, -0.5), (6, 6, 3.0), m, inside=True, shadow=False)
    return s


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_kernel_depth_equals_the_numpy_reference(seed):
    rng = np.random.default_rng(seed)
    s = _random_scene(rng)
    cs = s.compile()
    geo = PanoramaGeometry.square_pixels(180, 40)
    pos = np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), 0.6])
    depth, _, _ = render_depth(s, position=pos, geometry=geo)
    ref = trace_depth_reference(pos, _directions(geo).reshape(-1, 3), cs.boxes, cs.frusta, cs.ellipsoids)
    ref = ref.reshape(depth.shape)
    inside = np.isinf(ref) == np.isinf(depth)
    assert inside.mean() > 0.999
    ok = np.isfinite(ref) & np.isfinite(depth)
    close = np.isclose(depth[ok], ref[ok], rtol=1e-7, atol=1e-9)
    assert close.mean() > 0.999  # rays grazing an edge may pick the other face's distance


def test_rotation_is_a_column_roll():
    from bionav.world.worlds.lab import build_lab

    w = build_lab(0)
    geo = PanoramaGeometry.square_pixels(96, 16)
    pos = w.cell_position(3, 5)
    base = render_panorama(w.scene, position=pos, heading=0.0, geometry=geo)
    for k in (1, 17, 95):
        rot = render_panorama(w.scene, position=pos, heading=TWO_PI * k / geo.width, geometry=geo)
        np.testing.assert_array_equal(rot, np.roll(base, -k, axis=1))


def test_lambert_shading_and_hard_shadow():
    s = Scene()
    floor = s.material(albedo=0.5)
    s.box((-10, -10, -1), (10, 10, 0), floor, shadow=False)
    s.box((1.0, -0.3, 1.0), (1.6, 0.3, 1.05), s.material(albedo=0.5))  # a slab below the light
    s.add_light(PointLight((1.3, 0.0, 2.0), 4.0, downward=True))
    s.ambient = Ambient(up=0.1, down=0.1)
    geo = PanoramaGeometry.square_pixels(360, 120)
    pos = np.array([0.0, 0.0, 0.5])
    img = render_panorama(s, position=pos, geometry=geo, clip=False)[..., 0]
    depth, kind, idx = render_depth(s, position=pos, geometry=geo)
    d = _directions(geo)
    on_floor = (kind == 0) & (idx == 0)
    depth = np.where(on_floor, depth, 1.0)
    x = pos + d * depth[..., None]
    L = np.array([1.3, 0.0, 2.0])
    v = L - x
    dist = np.linalg.norm(v, axis=-1)
    cos = v[..., 2] / dist  # floor normal is +z and the emitter faces -z: both cosines are equal
    lit = 0.5 * (0.1 + 4.0 * cos * cos / dist ** 2)
    # shadowed where the segment to the light crosses the slab (z = 1.0 .. 1.05)
    tt = (1.0 - x[..., 2]) / v[..., 2]  # v_z > 0: the light is above the floor
    px = x[..., 0] + tt * v[..., 0]
    py = x[..., 1] + tt * v[..., 1]
    shadow = (px >= 1.0) & (px <= 1.6) & (np.abs(py) <= 0.3)
    expected = np.where(shadow, 0.5 * 0.1, lit)
    edge = (np.abs(px - 1.0) < 0.02) | (np.abs(px - 1.6) < 0.02) | (np.abs(np.abs(py) - 0.3) < 0.02)
    sel = on_floor & ~edge
    assert shadow[sel].sum() > 20
    np.testing.assert_allclose(img[sel], expected[sel], rtol=2e-3, atol=1e-6)


def test_directional_light_sky_and_channels():
    s = Scene(channels=("a", "b", "c"), sky=lambda d: np.tile([0.2, 0.4, 0.6], (len(d), 1)))
    s.box((-50, -50, -1), (50, 50, 0), s.material(albedo=(0.1, 0.2, 0.3)), shadow=False)
    s.add_light(DirectionalLight((0.0, 0.0, 1.0), (1.0, 2.0, 3.0)))
    s.ambient = Ambient(up=0.0, down=0.0)
    geo = PanoramaGeometry.square_pixels(64, 16)
    img = render_panorama(s, position=(0, 0, 1), geometry=geo, clip=False)
    assert img.shape == (16, 64, 3) and img.dtype == np.float32
    el = geo.row_elevations()
    up = el > 0
    np.testing.assert_allclose(img[up], np.broadcast_to([0.2, 0.4, 0.6], img[up].shape), rtol=1e-6)
    np.testing.assert_allclose(img[~up], np.broadcast_to([0.1, 0.4, 0.9], img[~up].shape), rtol=1e-5)


def test_supersampling_averages_sub_pixels():
    s = Scene()
    s.box((2.0, -1.0, 0.0), (2.2, 1.0, 1.5), s.material(albedo=0.5))
    s.ambient = Ambient(up=1.0, down=1.0)
    geo = PanoramaGeometry.square_pixels(90, 20)
    one = render_panorama(s, position=(0, 0, 0.5), geometry=geo)
    four = render_panorama(s, position=(0, 0, 0.5), geometry=geo, supersample=2)
    assert four.shape == one.shape
    # away from the wall's outline, sub-pixels agree; on the outline four gives partial coverage
    assert np.all((four == 0) | (four == 0.5) | ((four > 0) & (four < 0.5)))
    assert np.any((four > 0) & (four < 0.5))


def test_result_does_not_depend_on_the_number_of_threads():
    rng = np.random.default_rng(5)
    s = _random_scene(rng)
    s.add_light(PointLight((0.0, 0.0, 2.5), 3.0))
    geo = PanoramaGeometry.square_pixels(120, 30)
    one = render_panorama(s, position=(0.5, 0.5, 0.6), geometry=geo, threads=1)
    for threads in (2, 3, None):  # 8, 12 and 4 x cores blocks of columns (uneven at 3: 120 / 12 ... / 8)
        many = render_panorama(s, position=(0.5, 0.5, 0.6), geometry=geo, threads=threads)
        np.testing.assert_array_equal(one, many)
    # a grid narrower than the blocks (columns < 4 x threads) and one column
    narrow = PanoramaGeometry.square_pixels(5, 30)
    np.testing.assert_array_equal(render_panorama(s, position=(0.5, 0.5, 0.6), geometry=narrow, threads=1),
                                  render_panorama(s, position=(0.5, 0.5, 0.6), geometry=narrow, threads=4))


def test_stable_argsort_is_numpys_stable_order():
    from bionav.world.intersect import _stable_argsort

    rng = np.random.default_rng(3)
    for n in (0, 1, 2, 3, 7, 8, 9, 64, 257):
        for keys in (rng.random(n), rng.integers(0, 4, n).astype(float)):  # distinct keys, many ties
            if n > 3:
                keys[rng.integers(0, n, 2)] = np.nan  # NaN last, as numpy
            np.testing.assert_array_equal(_stable_argsort(keys), np.argsort(keys, kind="stable"))


@pytest.mark.slow
def test_binned_shadow_rays_equal_brute_force():
    from bionav.world.intersect import INF
    from bionav.world.shadow_bins import _occluded

    rng = np.random.default_rng(11)
    s = _random_scene(rng)
    s.add_light(PointLight((0.5, -0.5, 2.8), 1.0))
    s.add_light(PointLight((-2.0, 2.0, 2.5), 1.0, downward=False))
    s.add_light(DirectionalLight((0.3, -0.4, 0.8), 1.0))
    cs = s.compile()
    casters_only = [cs.boxes[cs.boxes[:, 9] > 0.5], cs.frusta[cs.frusta[:, 6] > 0.5],
                    cs.ellipsoids[cs.ellipsoids[:, 6] > 0.5]]
    n_blocked = 0
    for k in range(len(cs.light_params)):
        lp = cs.light_params[k]
        for _ in range(300):
            p = rng.uniform([-5, -5, 0], [5, 5, 2.5])
            if lp[0] < 0.5:
                v = lp[1:4] - p
                tmax = np.linalg.norm(v) - 1e-3
                d = v / np.linalg.norm(v)
            else:
                d, tmax = lp[1:4], INF
            binned = _occluded(k, *p, *d, tmax, cs.light_params, *cs.shadow_bins(), cs.prim_kind, cs.prim_idx,
                               cs.spheres, cs.boxes, cs.frusta, cs.ellipsoids)
            brute = trace_depth_reference(p, d[None], *casters_only)[0] < tmax
            assert binned == brute
            n_blocked += brute
    assert n_blocked > 20


def test_preparing_compiles_the_one_signature_of_every_render_and_builds_no_shadow_bins():
    from bionav.world.kernels import render_kernel
    from bionav.world.render import prepare_renderer

    rng = np.random.default_rng(8)
    s = _random_scene(rng)
    s.add_light(PointLight((0.0, 0.0, 2.5), 3.0))
    cs = s.compiled()
    before = set(render_kernel.signatures)
    prepare_renderer(cs)
    assert cs.shadow_grids is None  # the one-ray render casts no shadow ray: no bins built (nor compiled)
    prepared = set(render_kernel.signatures)
    assert len(prepared - before) <= 1
    img = render_panorama(cs, position=(0.5, 0.5, 0.6), geometry=PanoramaGeometry.square_pixels(40, 10))
    assert set(render_kernel.signatures) == prepared  # the real render compiled nothing more
    assert cs.shadow_grids is not None and np.isfinite(img).all()


def test_the_world_digest_leaves_out_the_derived_shadow_bins():
    rng = np.random.default_rng(9)
    s = _random_scene(rng)
    s.add_light(PointLight((0.0, 0.0, 2.5), 3.0))
    cs = s.compiled()
    lazy = cs.digest()
    cs.shadow_bins()
    assert cs.digest() == lazy  # the same key before and after the bins are built
    other = _random_scene(np.random.default_rng(9))
    other.add_light(PointLight((0.0, 0.0, 2.4), 3.0))
    assert other.compiled().digest() != lazy  # a light moved: another world


def test_map_in_threads_keeps_the_order_and_stops_when_the_caller_stops():
    import threading
    import time

    from bionav.world.render import map_in_threads

    ran = []
    lock = threading.Lock()

    def square(x):
        time.sleep(0.005 * (x % 3))  # finishing out of order
        with lock:
            ran.append(x)
        return x * x

    assert list(map_in_threads(square, range(20), threads=2)) == [x * x for x in range(20)]
    ran.clear()
    taken = map_in_threads(square, range(100), threads=2)
    assert [next(taken) for _ in range(3)] == [0, 1, 4]
    taken.close()  # the caller stops (an error, Ctrl-C): what was not started is cancelled
    time.sleep(0.2)
    assert len(ran) <= 3 + 2 * 2  # the three taken and at most 2 x threads handed out ahead
