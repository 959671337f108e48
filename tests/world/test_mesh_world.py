"""Mesh worlds: loading (.mat, .obj, .ply), the grid ray caster against brute force, terrain heights, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.io

from bionav.errors import UserError
from bionav.geometry import PanoramaGeometry
from bionav.world.mesh import load_mesh, mesh_from_arrays
from bionav.world.mesh_kernels import build_grid, trace_reference
from bionav.world.mesh_render import MeshWorld, cast_mesh_directions, cast_mesh_rays, render_mesh_panorama


def _random_soup(n, seed):
    rng = np.random.default_rng(seed)
    centres = rng.uniform([0, 0, 0], [6, 5, 1.5], size=(n, 3))
    return centres[:, None, :] + rng.normal(0, 0.15, size=(n, 3, 3))


def _directions(az, el):
    E, A = np.meshgrid(el, az, indexing="ij")
    return np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)


@pytest.mark.parametrize("origin", [(3.0, 2.5, 0.05), (2.0, 1.0, 0.8), (-3.0, 7.0, 0.3), (3.0, 2.5, 3.0)])
def test_grid_kernel_matches_brute_force(origin):
    tri = _random_soup(400, 1)
    world = MeshWorld(mesh_from_arrays(tri))
    az = np.linspace(0, 2 * np.pi, 97, endpoint=False)
    el = np.linspace(-0.6, 0.9, 23)
    depth, index = cast_mesh_directions(world, position=origin, azimuths=az, elevations=el)
    d_ref, i_ref = trace_reference(origin, _directions(az, el), tri, ground_z=0.0)
    assert (index.ravel() == i_ref).mean() > 0.999  # ties at shared edges may pick either triangle
    both = np.isfinite(d_ref)
    np.testing.assert_allclose(depth.ravel()[both], d_ref[both], rtol=1e-9, atol=1e-9)
    assert np.all(np.isinf(depth.ravel()[~both]))


def test_wall_at_known_distance():
    # a vertical wall x = 2, y in [-5, 5], z in [0, 3]; camera at the origin, height 0.5
    wall = np.array([[[2, -5, 0], [2, 5, 0], [2, 5, 3]], [[2, -5, 0], [2, 5, 3], [2, -5, 3]]], float)
    world = MeshWorld(mesh_from_arrays(wall, [0.2, 0.2]))
    el = np.deg2rad([-10.0, 0.0, 20.0])
    depth, index = cast_mesh_directions(world, position=(0, 0, 0.5), azimuths=[0.0, np.deg2rad(30), np.pi],
                                        elevations=el)
    np.testing.assert_allclose(depth[:, 0], 2.0 / np.cos(el))
    np.testing.assert_allclose(depth[1, 1], 2.0 / np.cos(np.deg2rad(30)))
    assert index[0, 2] == -2 and index[1, 2] == -1 and index[2, 2] == -1  # behind: ground below, sky above
    np.testing.assert_allclose(depth[0, 2], 0.5 / np.sin(np.deg2rad(10)))


def test_heading_is_a_column_roll_and_image_has_sky_ground_and_mesh():
    world = MeshWorld(mesh_from_arrays(_random_soup(300, 2)), channels="spectral")
    g = PanoramaGeometry.square_pixels(120, 24)
    v0 = render_mesh_panorama(world, position=(3, 2.5, 0.1), geometry=g)
    v = render_mesh_panorama(world, position=(3, 2.5, 0.1), heading=2 * np.pi * 17 / 120, geometry=g)
    assert v0.shape == (24, 120, 5)
    np.testing.assert_array_equal(v, np.roll(v0, -17, axis=1))
    _, index = cast_mesh_rays(world, position=(3, 2.5, 0.1), geometry=g)
    assert {-2, -1} <= set(np.unique(index)) and (index >= 0).any()
    # the UV band of the sky is brighter relative to vegetation than the IR band (default band tables)
    sky, veg = index == -1, index >= 0
    assert v0[sky][:, 0].mean() / v0[veg][:, 0].mean() > v0[sky][:, 4].mean() / v0[veg][:, 4].mean()


def test_grid_sizes_scale_with_triangles():
    g = build_grid(_random_soup(2000, 3))
    nx, ny = g["shape"]
    assert 500 <= nx * ny <= 2000 and g["starts"][-1] >= 2000


def test_terrain_height_and_missing_cells_on_a_sloped_mesh():
    # terrain z = 0.1 x + 0.05 y over [0, 4] x [0, 4]; a flat roof at z = 2 over [1, 2] x [1, 2]
    xs = np.linspace(0, 4, 9)
    tris = []
    for i in range(8):
        for j in range(8):
            p = [(xs[i], xs[j]), (xs[i + 1], xs[j]), (xs[i + 1], xs[j + 1]), (xs[i], xs[j + 1])]
            p = [(x, y, 0.1 * x + 0.05 * y) for x, y in p]
            tris += [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
    tris += [[(1, 1, 2), (2, 1, 2), (2, 2, 2)], [(1, 1, 2), (2, 2, 2), (1, 2, 2)]]
    world = MeshWorld(mesh_from_arrays(np.array(tris, float)), ground="mesh")
    xy = np.array([[0.3, 0.7], [3.1, 2.2], [1.5, 1.5], [6.0, 1.0]])
    z = world.terrain_height(xy)
    np.testing.assert_allclose(z[:3], 0.1 * xy[:3, 0] + 0.05 * xy[:3, 1], atol=1e-9)
    assert np.isnan(z[3])  # no terrain outside the mesh
    pos, free = world.camera_positions(xy, height=0.25)
    assert free.tolist() == [True, True, False, False]  # under the roof; off the terrain
    np.testing.assert_allclose(pos[:2, 2], z[:2] + 0.25)
    _, free_low = world.camera_positions(xy[2:3], height=0.25, clearance_m=1.0)
    assert free_low[0]  # the roof is 1.8 m above the terrain: free with a 1 m clearance


def _write_mesh_files(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(1, 1, 1))
    box.apply_translation((2, 2, 0.5))
    box.visual.face_colors = np.tile([200, 50, 50, 255], (len(box.faces), 1))
    ground = trimesh.Trimesh(vertices=[[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], faces=[[0, 1, 2], [0, 2, 3]],
                             process=False)
    ground.visual.face_colors = np.tile([100, 100, 100, 255], (2, 1))
    scene = trimesh.util.concatenate([box, ground])
    paths = {}
    for suffix in ("obj", "ply"):
        paths[suffix] = tmp_path / f"world.{suffix}"
        scene.export(paths[suffix])
    return scene, paths


def test_obj_and_ply_load_with_geometry_and_colours(tmp_path):
    scene, paths = _write_mesh_files(tmp_path)
    for suffix, path in paths.items():
        mesh = load_mesh(path)
        assert len(mesh) == len(scene.faces), suffix
        np.testing.assert_allclose(mesh.bounds, [[0, 0, 0], [4, 4, 1]], atol=1e-6)
        if suffix == "ply":  # .ply keeps face colours; .obj keeps them through its material where it can
            assert np.isclose(mesh.colors.max(axis=0)[0], 200 / 255, atol=0.01)
        world = MeshWorld(mesh, ground="mesh")
        pos, free = world.camera_positions([[0.5, 0.5], [2.0, 2.0]], height=0.2)
        assert free.tolist() == [True, False]  # inside the box: missing
        np.testing.assert_allclose(pos[0, 2], 0.2, atol=1e-9)
        d, _i = cast_mesh_directions(world, position=pos[0], azimuths=[np.pi / 4], elevations=[0.0])
        np.testing.assert_allclose(d[0, 0], np.hypot(1.0, 1.0), atol=1e-6)  # box corner at (1.5, 1.5)


def test_mat_layout_roundtrip_uses_abs_z(tmp_path):
    tri = _random_soup(50, 4)
    tri[0, 0, 2] = -0.3
    path = tmp_path / "w.mat"
    scipy.io.savemat(path, {"X": tri[..., 0], "Y": tri[..., 1], "Z": tri[..., 2], "colp": np.full((50, 3), 0.4)})
    mesh = load_mesh(path)
    assert mesh.triangles[0, 0, 2] == pytest.approx(0.3)
    np.testing.assert_allclose(mesh.triangles[1:], np.concatenate([tri[1:, :, :2], np.abs(tri[1:, :, 2:])], -1))
    np.testing.assert_allclose(mesh.grey, 0.4)


@pytest.mark.parametrize("case, needle", [
    ("garbage.obj", "holds no triangles"),
    ("cloud.ply", "holds no triangles"),
    ("nan.mat", "NaN"),
    ("empty.mat", "no triangles"),
    ("noxyz.mat", "lacks the variable"),
    ("text.mat", "not a readable MATLAB"),
    ("world.stl", "unknown mesh format"),
    ("missing.obj", "does not exist"),
])
def test_bad_mesh_files_give_one_clear_message(tmp_path, case, needle):
    path = tmp_path / case
    if case == "garbage.obj":
        path.write_text("this is not a mesh\n")
    elif case == "cloud.ply":
        trimesh = pytest.importorskip("trimesh")
        trimesh.PointCloud(np.random.default_rng(0).uniform(size=(20, 3))).export(path)
    elif case == "nan.mat":
        t = _random_soup(5, 0)
        t[2, 1, 0] = np.nan
        scipy.io.savemat(path, {"X": t[..., 0], "Y": t[..., 1], "Z": t[..., 2]})
    elif case == "empty.mat":
        scipy.io.savemat(path, {"X": np.zeros((0, 3)), "Y": np.zeros((0, 3)), "Z": np.zeros((0, 3))})
    elif case == "noxyz.mat":
        scipy.io.savemat(path, {"A": np.zeros((3, 3))})
    elif case in ("text.mat", "world.stl"):
        path.write_text("solid nothing\n")
    with pytest.raises(UserError, match=needle):
        load_mesh(path)


def test_mesh_bench_cli_reports_cpu_and_wall(capsys):
    import json

    from bionav.bench.mesh import main

    assert main(["--json", "--grid", "2", "--repeat", "1", "--threads", "1"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["benchmark"] for r in rows] == ["panorama", "grid_2x2", "panorama_50k"]
    assert rows[0]["triangles"] == 5000 and rows[2]["triangles"] == 50_000
    assert all(r["cpu_ms"] > 0 and r["wall_ms"] > 0 for r in rows)
