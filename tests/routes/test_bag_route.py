"""experiment=route_homing db=bag: a drive recorded in a rosbags-written bag, followed with the published protocol."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from helpers import assert_fails_cleanly, run_bionav
from rosbag_helpers import T0_NS, write_drive

pytest.importorskip("rosbags")

from bionav.db.bag.route import RecordedViews, route_stations  # noqa: E402


def test_route_stations_every_step_of_path_length():
    xy = np.array([[0.0, 0.0], [0.04, 0.0], [0.09, 0.0], [0.11, 0.0], [0.2, 0.0], [0.2, 0.15], [0.2, 0.18]])
    # path length 0, .04, .09, .11, .2, .35, .38: the first view at or after 0, .1, .2, .3; the last view
    assert route_stations(xy, 0.1).tolist() == [0, 3, 4, 5, 6]
    assert route_stations(xy, 1.0).tolist() == [0, 6]


def test_recorded_views_turned_to_a_heading():
    rng = np.random.default_rng(0)
    images = rng.random((3, 4, 36)).astype(np.float32)
    world = RecordedViews(images, np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), np.array([0.0, 0.5, 1.0]))
    assert world.nearest([1.4, 0.3]) == 1 and world.nearest([0.5, 0.0]) == 0  # a tie goes to the earlier view
    # view 2 was taken at heading 1.0; asked for heading 1.0 + 3 columns it is that view rolled by -3 columns
    turned = world.render([2.2, 0.0], 1.0 + 3 * 2 * math.pi / 36)
    assert np.array_equal(turned, np.roll(images[2], -3, axis=-1))
    half = world.render([0.0, 0.0], 0.5 * 2 * math.pi / 36)  # half a column: the mean of two neighbours
    assert np.allclose(half, 0.5 * (images[0] + np.roll(images[0], -1, axis=-1)), atol=1e-6)


def _path(s: float):
    x = -2.2 + 4.0 * s
    return x, -0.3 + 0.25 * math.sin(2.0 * x)


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    """81 views along a 4.3 m wavy drive through the pillar room (one every 5.4 cm), odometry at 20 Hz."""
    from bionav.testing import render_pillar_panorama

    n = 81
    images = []
    for k in range(n):
        img, _ = render_pillar_panorama(_path(k / (n - 1)), width=360, height=40, supersample=1)
        images.append((T0_NS + k * 2 * 10**8, np.uint8(np.rint(img * 255))))
    poses = []
    for k in range(4 * n + 4):
        t = T0_NS - 10**8 + k * 5 * 10**7 + 3 * 10**6
        poses.append((t, *_path(min(max((t - T0_NS) / (2 * 10**8 * (n - 1)), 0.0), 1.0)), 0.0))
    return write_drive(tmp_path_factory.mktemp("route") / "drive", "sqlite3", images=images, poses=poses,
                       encoding="png")


ROUTE = ("experiment=route_homing", "experiment.protocol=ardin2016", "db=bag", "db.image_topic=/camera/image",
         "db.pose_topic=/odom", "db.route_step_m=0.1", "db.azimuth=counterclockwise")


@pytest.mark.slow
def test_a_drive_from_a_bag_is_followed(tmp_path, drive):
    proc = run_bionav(*ROUTE, f"db.path={drive}", "experiment.agents=[perfect_memory,infomax,mfdid]",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    m = json.loads((tmp_path / "run" / "metrics.json").read_text())
    assert m["routes"] == ["drive_camera_image"] and m["protocol"] == "ardin2016"
    for agent in ("perfect_memory", "infomax", "mfdid"):
        assert m[f"reached_nest_{agent}"] == 1.0, agent
    assert m["errors_per_route_perfect_memory"] == 0 and m["errors_per_route_infomax"] == 0
    rows = (tmp_path / "run" / "route_following.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[1].startswith("drive_camera_image,perfect_memory,0,")
    views = np.array([_path(k / 80) for k in range(81)])
    length = np.linalg.norm(np.diff(views, axis=0), axis=1).sum()  # 4.29 m
    first = dict(zip(rows[0].split(","), rows[1].split(",")))
    assert int(first["n_views"]) == math.ceil(length / 0.1) + 1  # a route view every 0.1 m, and the last
    assert (tmp_path / "run" / "plots" / "world_routes.png").is_file()


@pytest.mark.slow
def test_route_options_that_do_not_fit_a_bag(tmp_path, drive):
    bionav = [a for a in ROUTE if not a.startswith("experiment.protocol")]
    proc = run_bionav(*bionav, f"db.path={drive}", f"hydra.run.dir={tmp_path / 'a'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "experiment.protocol=ardin2016", "recorded drive")
    proc = run_bionav(*ROUTE, f"db.path={drive}", "experiment.routes=[Ant1_Route1]", f"hydra.run.dir={tmp_path / 'b'}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "drop experiment.routes")


@pytest.mark.slow
def test_a_second_world_on_the_robustness_sweep(tmp_path, drive):
    """experiment.worlds puts a second world on the sweep (axis ``world``): the agents follow Ant1_Route1 in the
    Seville world and the bag's drive through the pillar room, where the known answer holds (perfect memory and
    infomax: no put-back, the nest reached, as in the drive's own run above). robustness.csv sets the two worlds
    side by side from the rows of each; the figure's lines are those numbers."""
    import csv

    from bionav.experiments.route_homing.plots import plot_robustness

    world = (f"+experiment.worlds.pillars={{db:bag,path:{drive},image_topic:/camera/image,pose_topic:/odom,"
             "route_step_m:0.1}")
    proc = run_bionav("experiment=route_homing", "experiment.protocol=ardin2016", "experiment.routes=[Ant1_Route1]",
                      "experiment.agents=[perfect_memory,infomax]", world, f"cache_dir={tmp_path / 'cache'}",
                      f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    run = tmp_path / "run"
    rows = list(csv.DictReader((run / "route_following.csv").open()))
    assert [(r["route"], r["agent"], r["axis"], r["level"]) for r in rows] == [
        ("Ant1_Route1", "perfect_memory", "", ""), ("Ant1_Route1", "infomax", "", ""),
        ("drive_camera_image", "perfect_memory", "world", "pillars"), ("drive_camera_image", "infomax", "world", "pillars")]
    for r in rows[2:]:
        assert r["errors"] == "0" and r["reached_nest"] == "1", r
    summary = [s for s in csv.DictReader((run / "robustness.csv").open()) if s["axis"] == "world"]
    assert [(s["level"], s["agent"]) for s in summary] == [("seville2009", "perfect_memory"), ("seville2009", "infomax"),
                                                           ("pillars", "perfect_memory"), ("pillars", "infomax")]
    for s, r in zip(summary, rows):
        assert float(s["errors_median"]) == float(r["errors"]) and float(s["reached_nest"]) == float(r["reached_nest"])
    lines = plot_robustness(tmp_path / "w.png", summary, axis="world", unit="", agents=["perfect_memory", "infomax"],
                            categories=["seville2009", "pillars"])
    for agent, (x, med, nest) in lines.items():
        mine = [s for s in summary if s["agent"] == agent]
        assert x.tolist() == [0.0, 1.0] and med.tolist() == [float(s["errors_median"]) for s in mine]
        assert nest.tolist() == [100.0 * float(s["reached_nest"]) for s in mine]
    assert (run / "plots" / "robustness_world.png").is_file()
    m = json.loads((run / "metrics.json").read_text())
    assert m["sweep"] == {"world": ["seville2009", "pillars"]} and m["n_conditions"] == 2


def test_a_bad_second_world_is_one_clear_message(tmp_path):
    base = ("experiment=route_homing", "experiment.protocol=ardin2016", "experiment.routes=[Ant1_Route1]",
            "experiment.agents=[perfect_memory]")
    proc = run_bionav(*base, "+experiment.worlds.x={db:nosuchdb}", f"hydra.run.dir={tmp_path / 'a'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "experiment.worlds.x.db", "nosuchdb")
    proc = run_bionav(*base, "+experiment.worlds.x={db:bag,path:" + str(tmp_path / "missing") + "}",
                      f"hydra.run.dir={tmp_path / 'b'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "missing")
    proc = run_bionav("experiment=route_homing", "+experiment.worlds.x={db:bag}", f"hydra.run.dir={tmp_path / 'c'}",
                      cwd=tmp_path)
    assert_fails_cleanly(proc, "experiment.protocol=ardin2016")
