"""SIFT homing's windowed matcher and all-pairs path against the plain all-against-all reference.

Real OpenCV SIFT keypoints of rendered laboratory panoramas (plain and
histogram-equalised); the fast matcher must return exactly the matches of
:func:`match_in_neighbourhood_reference`, and the compiled home-vector kernels
the home angles of the numpy composition (eqs. 5.12-5.15).
"""

import numpy as np
import pytest

from bionav.geometry import PanoramaGeometry
from bionav.homing import sift_homing as sh
from bionav.homing.features import SiftFeatures, sift_features
from bionav.homing.imageops import equalize_histogram

CELLS = [(4, 8), (7, 8), (2, 10), (5, 4), (4, 9)]


@pytest.fixture(scope="module")
def rendered():
    from bionav.world.render import render_panorama
    from bionav.world.worlds.lab import build_lab

    world = build_lab(0)
    geometry = PanoramaGeometry.square_pixels(561, 81)
    images = []
    for cell in CELLS:
        img = render_panorama(world.scene, position=world.cell_position(*cell), heading=0.0, geometry=geometry)
        images.append(img[..., 0] if img.ndim == 3 else img)
    return geometry, images


@pytest.fixture(scope="module", params=["plain", "histeq"])
def features(request, rendered):
    geometry, images = rendered
    if request.param == "histeq":
        images = [equalize_histogram(im) for im in images]
    feats = [sift_features(im) for im in images]
    assert min(len(f.xy) for f in feats) > 50
    return geometry, feats


def _same(a, b):
    return np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


@pytest.mark.parametrize("fraction", [0.05, 0.22, 0.45, 0.6])
def test_fast_matcher_equals_brute_force_on_opencv_sift(features, fraction):
    geometry, feats = features
    radius = fraction * geometry.width
    n_matches = 0
    for c in range(len(feats)):
        for s in range(len(feats)):
            fast = sh.match_in_neighbourhood(feats[c], feats[s], radius=radius, width=geometry.width)
            ref = sh.match_in_neighbourhood_reference(feats[c], feats[s], radius=radius, width=geometry.width)
            assert _same(fast, ref), (c, s)
            n_matches += len(fast[0])
    assert n_matches > 100


def test_reference_keeps_only_keypoints_inside_the_radius(features):
    geometry, feats = features
    radius = 0.1 * geometry.width
    ci, si = sh.match_in_neighbourhood_reference(feats[0], feats[1], radius=radius, width=geometry.width)
    dx = np.abs(feats[0].xy[ci, 0].astype(float) - feats[1].xy[si, 0])
    dx = np.minimum(dx, geometry.width - dx)
    dy = feats[0].xy[ci, 1].astype(float) - feats[1].xy[si, 1]
    assert len(ci) > 10 and np.all(dx * dx + dy * dy < radius * radius)
    # every chosen keypoint is the descriptor-nearest one among those inside
    c = feats[0].descriptors[ci[0]].astype(float)
    inside = [j for j in range(len(feats[1].xy))
              if min(abs(feats[0].xy[ci[0], 0] - feats[1].xy[j, 0]),
                     geometry.width - abs(feats[0].xy[ci[0], 0] - feats[1].xy[j, 0])) ** 2
              + (feats[0].xy[ci[0], 1] - feats[1].xy[j, 1]) ** 2 < radius ** 2]
    dist = [np.sum((c - feats[1].descriptors[j]) ** 2) for j in inside]
    assert inside[int(np.argmin(dist))] == si[0]


def _features(xy, desc):
    desc = np.asarray(desc, np.float32)
    return SiftFeatures(np.asarray(xy, np.float32), desc, np.einsum("ij,ij->i", desc, desc))


def test_ties_go_to_the_lowest_snapshot_index_whatever_the_column_order():
    rng = np.random.default_rng(3)
    base = rng.integers(0, 200, (3, 128))
    # snapshot keypoints 0, 2 and 4 carry the same descriptor (exact tie), listed right to left
    snap_desc = [base[0], base[1], base[0], base[2], base[0]]
    snap_xy = [(90.0, 10.0), (80.0, 10.0), (70.0, 12.0), (60.0, 10.0), (5.0, 10.0)]
    cur = _features([(75.0, 11.0), (98.0, 11.0)], [base[0], base[0]])
    snap = _features(snap_xy, snap_desc)
    fast = sh.match_in_neighbourhood(cur, snap, radius=30.0, width=100)
    ref = sh.match_in_neighbourhood_reference(cur, snap, radius=30.0, width=100)
    assert _same(fast, ref)
    # keypoint 0 (x=75) sees 0, 2 and 4 (x=5 is 30 px away: outside); keypoint 1 (x=98) sees 0 and 4 (wrap)
    assert fast[0].tolist() == [0, 1] and fast[1].tolist() == [0, 0]
    far = sh.match_in_neighbourhood(_features([(40.0, 10.0)], [base[0]]), snap, radius=10.0, width=100)
    assert far[0].size == 0 and far[1].size == 0


def test_non_integer_descriptors_and_keypoints_outside_the_image_fall_back_exactly():
    rng = np.random.default_rng(5)
    cur = _features(rng.uniform(-3, 103, (40, 2)), rng.integers(0, 255, (40, 128)))
    snap = _features(rng.uniform(0, 100, (50, 2)), rng.integers(0, 255, (50, 128)))
    assert _same(sh.match_in_neighbourhood(cur, snap, radius=25.0, width=100),
                 sh.match_in_neighbourhood_reference(cur, snap, radius=25.0, width=100))
    assert sh.column_index(_features(rng.uniform(0, 100, (5, 2)), rng.uniform(0, 1, (5, 128)))) is None
    frac = _features(rng.uniform(0, 100, (30, 2)), rng.uniform(0, 1, (30, 128)))
    frac2 = _features(rng.uniform(0, 100, (30, 2)), rng.uniform(0, 1, (30, 128)))
    assert _same(sh.match_in_neighbourhood(frac, frac2, radius=25.0, width=100),
                 sh.match_in_neighbourhood_reference(frac, frac2, radius=25.0, width=100))


@pytest.mark.parametrize("combine", ["average", "max"])
def test_compiled_home_vector_equals_numpy_composition(features, combine):
    geometry, feats = features
    radius = 0.22 * geometry.width
    for c in range(len(feats)):
        for s in range(len(feats)):
            if s == c:
                continue
            fast = sh.sift_home_vector(feats[s], feats[c], geometry=geometry, search_radius=radius, combine=combine)
            ref = sh.sift_home_vector_reference(feats[s], feats[c], geometry=geometry, search_radius=radius,
                                                combine=combine)
            assert fast[1] == ref[1] > 10
            assert fast[0] == pytest.approx(ref[0], abs=1e-12)


@pytest.mark.parametrize("combine", ["average", "max"])
def test_all_pairs_equal_pair_by_pair_with_any_worker_count(features, combine):
    geometry, feats = features
    radius = 0.22 * geometry.width
    one, used_one = sh.sift_home_angles_all_pairs(feats, geometry=geometry, search_radius=radius, combine=combine)
    two, used_two = sh.sift_home_angles_all_pairs(feats, geometry=geometry, search_radius=radius, combine=combine,
                                                  workers=2)
    assert np.array_equal(one, two, equal_nan=True) and np.array_equal(used_one, used_two)
    n = len(feats)
    assert np.all(np.isnan(np.diag(one)))
    for s in range(n):
        for c in range(n):
            if s != c:
                angle, used = sh.sift_home_vector(feats[s], feats[c], geometry=geometry, search_radius=radius,
                                                  combine=combine)
                assert one[s, c] == angle and used_one[s, c] == used
    rows, _ = sh.sift_home_angles_all_pairs(feats, geometry=geometry, search_radius=radius, combine=combine,
                                            snapshot_index=[3], workers=2)
    assert np.array_equal(rows[3], one[3], equal_nan=True)
    assert np.all(np.isnan(np.delete(rows, 3, axis=0)))


def test_grid_runner_batch_path_equals_per_pair_calls(rendered):
    from bionav.db.database import ImageDatabase
    from bionav.evaluation.pairs import home_vector_matrix
    from bionav.plugins.homing.sift import SiftConfig, SiftHoming

    geometry, images = rendered
    positions = np.array(CELLS)
    db = ImageDatabase(name="lab5", images=np.stack(images), positions=positions, geometry=geometry,
                       grid_shape=(10, 17))
    method = SiftHoming(SiftConfig(), geometry=geometry)
    streamed = []
    batch = home_vector_matrix(method, db, workers=2, snapshot_index=[2, 0],
                               on_row=lambda s, angles, compass: streamed.append((s, angles, compass)))
    pairs = home_vector_matrix(method, db, workers=2, snapshot_index=[2, 0], batch=False)
    assert np.allclose(batch.angles, pairs.angles, atol=1e-12, equal_nan=True)
    assert np.isnan(batch.angles[1, 0]) and np.isnan(batch.angles[0, 2])
    assert np.sum(np.isfinite(batch.angles)) == 8
    # each snapshot row reaches on_row once, as soon as it is complete (ascending index), with the final angles
    assert [s for s, _, _ in streamed] == [0, 2]
    assert np.array_equal(streamed[0][1], batch.angles[1], equal_nan=True)
    assert np.array_equal(streamed[1][1], batch.angles[0], equal_nan=True)
    assert all(np.all(np.isnan(compass)) for _, _, compass in streamed)


def test_rows_are_handed_out_as_soon_as_complete(features):
    geometry, feats = features
    seen = []

    def on_row(s, angles, used):
        # row s needs the pairs (c, s) of rows c < s and its own; later rows are not finished yet
        seen.append(s)
        assert np.isnan(angles[s]) and np.all(np.isfinite(np.delete(angles, s))) and np.all(np.delete(used, s) > 0)

    full, _ = sh.sift_home_angles_all_pairs(feats, geometry=geometry, search_radius=0.22 * geometry.width, workers=2,
                                            on_row=on_row)
    assert seen == list(range(len(feats)))
