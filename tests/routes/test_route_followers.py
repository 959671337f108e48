"""Homing followers built on the thesis' methods, the random-choice baseline and the protocol's robustness knobs.

Known answers on the analytic pillar room (bionav.testing.pillar_scene): a homing follower that has passed its
target view skips to the next one, the route direction blends with the home direction as computed by hand, and
every homing method with the follower's defaults walks a bent route without a put-back; the protocol's heading
noise and start offset move the agent exactly as their random draws say.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_route_agents import L_ROUTE, _pillar_render, _travel, _walk

from bionav.evaluation.route import follow_route, scan_offsets
from bionav.evaluation.route_followers import FamiliarityFollower, HomingFollower
from bionav.geometry import PanoramaGeometry

#: a straight route along +x at y = -0.5 in the pillar room, views every 0.1 m facing +x
STRAIGHT = np.column_stack([np.linspace(-2.0, 0.0, 21), np.full(21, -0.5)])


class _Oracle(HomingFollower):
    """A follower whose home direction to view ``j`` is the true one (the rest: the follower's own logic)."""

    def _home(self, xy, j):
        d = self.snapshots_xy[j] - np.asarray(xy, float)
        return math.atan2(d[1], d[0])


def _oracle(route, **kw):
    render = _pillar_render(180, 20)
    heading = _travel(route)
    f = _Oracle(_NoHoming(), snapshots=np.stack([render(p, h) for p, h in zip(route, heading)]),
                snapshot_headings=heading, render=render, window=kw.pop("window", 5), test_step_m=0.05,
                max_turn=math.radians(60), **kw)
    f.snapshots_xy = route
    return f


class _NoHoming:
    """Nothing to prepare: the oracle knows the answer."""

    uses_test_steps = False

    @staticmethod
    def prepare(image):
        return None


def test_a_passed_target_view_is_skipped_and_a_kept_one_turns_the_agent_round():
    """At x = -1.17 (3 cm past view 8, 7 cm before view 9) the views' RIDF finds view 8; with lookahead 0 the
    target is view 8, which lies behind: its true home direction is 180 deg, more than 90 deg off the route's
    0 deg, so ``passed="skip"`` homes to view 9 (0 deg) and the agent keeps heading 0; ``passed="keep"`` homes to
    view 8 and turns by the most the scan allows, 60 deg."""
    xy = np.array([-1.17, -0.5])
    skip = _oracle(STRAIGHT, lookahead=0, passed="skip")
    skip.last = 7
    h, j = skip.target_direction(xy)
    assert skip.last == 8 and j == 9 and h == pytest.approx(0.0, abs=1e-12)
    assert skip(xy, 0.0) == pytest.approx(0.0, abs=1e-12)
    keep = _oracle(STRAIGHT, lookahead=0, passed="keep")
    keep.last = 7
    h, j = keep.target_direction(xy)
    assert j == 8 and abs(h) == pytest.approx(math.pi)
    assert abs(keep(xy, 0.0)) == pytest.approx(math.radians(60))


def test_skipping_stops_after_max_skip_views():
    """Far past the end of its window (x = -0.55, views 13..15 all behind the target test) the follower skips at
    most ``max_skip`` views: from target 10 (lookahead 2 after view 8, the window's farthest match from view 3)
    to 11 and 12, both behind, so it homes to view 12 backwards."""
    f = _oracle(STRAIGHT, lookahead=2, passed="skip", max_skip=2, window=5)
    f.last = 3
    h, j = f.target_direction(np.array([-0.55, -0.5]))
    assert f.last == 8 and j == 12 and abs(h) == pytest.approx(math.pi)


@pytest.mark.parametrize("weight", [0.0, 0.5, 1.0])
def test_route_direction_blends_with_the_home_direction_as_computed_by_hand(weight):
    """0.1 m left of the route at x = -1.0: the true home direction to the target view j (ahead) is
    atan2(-0.1, x_j + 1.0); the route there runs along 0 deg. The heading is the direction of
    (1 - w) u_home + w u_route: w = 0 homes, w = 1 follows the stored direction, w = 0.5 bisects."""
    f = _oracle(STRAIGHT, lookahead=2, passed="skip", route_weight=weight)
    f.last = 8
    xy = np.array([-1.0, -0.4])
    h_home, j = f.target_direction(xy)
    f.last = 8
    heading = f(xy, 0.0)
    home = math.atan2(-0.1, STRAIGHT[j, 0] + 1.0)
    assert h_home == pytest.approx(home, abs=1e-12) and j > 10
    want = math.atan2((1 - weight) * math.sin(home), (1 - weight) * math.cos(home) + weight)
    assert heading == pytest.approx(want, abs=1e-12)
    if weight == 0.5:
        assert heading == pytest.approx(home / 2, abs=1e-12)  # the bisector of two unit vectors


@pytest.mark.slow
@pytest.mark.parametrize("name", ["mfdid", "minwarping", "sift", "parameter"])
def test_each_homing_method_follows_the_bent_route_with_the_follower_defaults(name):
    """The follower of the ardin2016 defaults (passed views skipped, the home direction blended half and half
    with the stored route direction, progress searched 5 views ahead) on the bent pillar route: no put-back and
    the nest within 32 steps, never 0.15 m from the route (measured: at most 0.14 m for MFDID, 0.11 m for
    parameter homing, under 0.1 m for the others; the put-back distance is 0.2 m)."""
    from bionav.config import plugin_config
    from bionav.evaluation.route import distance_to_route

    render = _pillar_render(180, 40)
    cls, config = plugin_config("homing", {"name": name})
    homing = cls(config, geometry=PanoramaGeometry.square_pixels(180, 40))
    heading = _travel(L_ROUTE)
    snaps = np.stack([render(p, h) for p, h in zip(L_ROUTE, heading)])
    follower = HomingFollower(homing, snapshots=snaps, snapshot_headings=heading, render=render, window=5,
                              lookahead=2, test_step_m=0.05, max_turn=math.radians(60), passed="skip", route_weight=0.5)
    run = _walk(follower, L_ROUTE, heading)
    assert run.errors == 0 and run.reached_nest and run.steps <= 32, (run.errors, run.steps)
    assert distance_to_route(run.path, L_ROUTE)[0].max() < 0.15


def test_follower_options_are_checked():
    with pytest.raises(ValueError, match="passed"):
        _oracle(STRAIGHT, lookahead=1, passed="jump")
    with pytest.raises(ValueError, match="route_weight"):
        _oracle(STRAIGHT, lookahead=1, route_weight=1.5)


# --------------------------------------------------------------------------- the random-choice baseline
def test_random_choice_draws_every_scan_heading_alike_and_renders_nothing():
    """The baseline never looks (its views function would fail); over 6,100 choices each of the 61 scan offsets
    (+-60 deg in 2 deg) comes up about 100 times (Poisson: within 100 +- 45), and the mean offset is ~0."""
    from bionav.config import plugin_config

    cls, config = plugin_config("route_agent", {"name": "random_choice"})
    agent = cls(config, rng=np.random.default_rng(5))
    agent.train(np.zeros((0, 0)))

    def no_views(xy, heading):
        raise AssertionError("random_choice needs no views")

    off = scan_offsets(scan_half_deg=60.0, scan_step_deg=2.0)
    f = FamiliarityFollower(agent, no_views, offsets=off)
    chosen = np.array([f(np.zeros(2), 0.0) for _ in range(6100)])
    counts = np.array([np.sum(np.isclose(chosen, o)) for o in off])
    assert len(off) == 61 and counts.sum() == 6100 and counts.min() >= 55 and counts.max() <= 145
    assert abs(np.degrees(chosen.mean())) < 2.0
    with pytest.raises(ValueError, match="offsets"):
        FamiliarityFollower(agent, no_views)


def test_random_choice_is_put_back_on_a_straight_route():
    """Walking random headings of +-60 deg from the start, an agent drifts 0.2 m off a 3 m route within a few steps:
    seed 0 is put back 6 times in 39 steps (measured), where every trained agent walks this route without one."""
    from bionav.config import plugin_config

    route = np.column_stack([np.arange(31) * 0.1, np.zeros(31)])
    cls, config = plugin_config("route_agent", {"name": "random_choice"})
    agent = cls(config, rng=np.random.default_rng(0))
    f = FamiliarityFollower(agent, None, offsets=scan_offsets(scan_half_deg=60.0, scan_step_deg=2.0))
    run = follow_route(f, route_xy=route, route_heading=np.zeros(31), nest_xy=route[-1], step_m=0.1, putback_m=0.2,
                       goal_m=0.2, max_steps=200, on_putback=f.reset)
    assert run.errors >= 3 and run.reached_nest


# --------------------------------------------------------------------------- the protocol's robustness knobs
def test_heading_noise_and_start_offset_move_the_agent_as_drawn():
    """An agent that always chooses heading 0 on a route along +x, started 0.05 m to the left: each step walks
    along 0 + e_k, e_k the k-th normal draw of std 10 deg of the run's stream, so position k is the start plus
    0.1 (cos, sin) summed over e_1..e_k (no jitter, no put-back within 5 steps)."""
    route = np.column_stack([np.arange(31) * 0.1, np.zeros(31)])
    sigma = math.radians(10.0)
    run = follow_route(lambda p, h: 0.0, route_xy=route, route_heading=np.zeros(31), nest_xy=route[-1], step_m=0.1,
                       putback_m=0.2, goal_m=0.2, max_steps=5, heading_noise=sigma, start_offset_m=0.05,
                       rng=np.random.default_rng(3))
    e = np.random.default_rng(3).normal(0.0, sigma, 5)
    want = np.array([0.0, 0.05]) + np.cumsum(0.1 * np.column_stack([np.cos(e), np.sin(e)]), axis=0)
    np.testing.assert_allclose(run.path[0], [0.0, 0.05])
    np.testing.assert_allclose(run.path[1:], want, atol=1e-12)
    assert run.errors == 0
    with pytest.raises(ValueError, match="rng"):
        follow_route(lambda p, h: 0.0, route_xy=route, route_heading=np.zeros(31), nest_xy=route[-1], step_m=0.1,
                     putback_m=0.2, goal_m=0.2, max_steps=5, heading_noise=sigma)


def test_training_indices_keep_every_kth_view_and_the_nest():
    from bionav.experiments.route_homing.units import training_indices

    np.testing.assert_array_equal(training_indices(10, 1), np.arange(10))
    np.testing.assert_array_equal(training_indices(10, 4), [0, 4, 8, 9])
    np.testing.assert_array_equal(training_indices(9, 4), [0, 4, 8])
    np.testing.assert_array_equal(training_indices(83, 8), [0, 8, 16, 24, 32, 40, 48, 56, 64, 72, 80, 82])


# --------------------------------------------------------------------------- the run: figure, tables, sweep
def test_the_figures_draw_what_their_csv_files_hold(tmp_path):
    """errors_per_route.png draws one dot per row of errors_per_route.csv per agent (written and read back as the
    run does); each robustness_<axis>.png line goes through robustness.csv's medians and nest arrivals (in %)."""
    import csv

    from bionav.experiments.route_homing.plots import plot_errors_per_route, plot_robustness
    from bionav.experiments.route_homing.robustness import ROBUSTNESS_KEYS
    from bionav.experiments.route_homing.shared import write_rows

    agents = ["perfect_memory", "random_choice"]
    rows = [{"route": f"Ant{k}_Route1", "seed": 0, "perfect_memory": k % 3, "random_choice": 20 + 2 * k}
            for k in range(1, 8)]
    write_rows(tmp_path / "errors_per_route.csv", rows, ["route", "seed", *agents])
    table = list(csv.DictReader((tmp_path / "errors_per_route.csv").open()))
    drawn = plot_errors_per_route(tmp_path / "e.png", table, agents, title="t")
    assert drawn["perfect_memory"].tolist() == [1, 2, 0, 1, 2, 0, 1]
    assert drawn["random_choice"].tolist() == [22, 24, 26, 28, 30, 32, 34]
    assert (tmp_path / "e.png").stat().st_size > 5_000
    summary = [{"axis": "heading_noise_deg", "level": lv, "agent": a, "runs": 7, "errors_median": m,
                "errors_q25": m - 1.0, "errors_q75": m + 1.0, "errors_mean": m, "error_free_routes": 0.0,
                "reached_nest": nest, "cpu_s_per_route": 1.0}
               for a, base in (("perfect_memory", 0.0), ("random_choice", 20.0))
               for lv, m, nest in ((20.0, base + 3.0, 0.5), (0.0, base, 1.0), (10.0, base + 1.0, 6 / 7))]
    write_rows(tmp_path / "robustness.csv", summary, ROBUSTNESS_KEYS)
    back = list(csv.DictReader((tmp_path / "robustness.csv").open()))
    lines = plot_robustness(tmp_path / "r.png", back, axis="heading_noise_deg", unit="deg", agents=agents)
    for a, base in (("perfect_memory", 0.0), ("random_choice", 20.0)):
        x, med, nest = lines[a]
        np.testing.assert_allclose(x, [0.0, 10.0, 20.0])  # sorted by level
        np.testing.assert_allclose(med, [base, base + 1.0, base + 3.0])
        np.testing.assert_allclose(nest, [100.0, 100 * 6 / 7, 50.0], atol=1e-4)  # the CSV's 6 decimals


@pytest.mark.slow
def test_ardin2016_run_writes_the_figure_the_per_route_table_and_a_sweep(tmp_path):
    """One route, three agents, two seeds, a jitter axis and a training-stride axis on two workers. The
    per-route table holds every run's errors as integers and agrees with route_following.csv; the boxplot's
    dots are those numbers; robustness.csv summarises each level from the rows of its condition (the level
    equal to the run's own setting from the run's rows); every random stream depends on the route, agent and
    seed only, so the run's own rows equal those of a run without the sweep on one worker."""
    import csv
    import json

    from helpers import run_bionav

    from bionav.experiments.route_homing.plots import plot_errors_per_route

    common = ["experiment=route_homing", "experiment.protocol=ardin2016", "experiment.routes=[Ant2_Route1]",
              "experiment.agents=[perfect_memory,random_choice,mfdid]", "experiment.seeds=[0,1]",
              f"cache_dir={tmp_path / 'cache'}"]
    sweep = run_bionav(*common, "+experiment.sweep.position_jitter_m=[0,0.02]",
                       "+experiment.sweep.training_stride=[1,4]", "workers=2", f"hydra.run.dir={tmp_path / 'sweep'}",
                       cwd=tmp_path)
    assert sweep.returncode == 0, sweep.stderr[-3000:]
    plain = run_bionav(*common, "workers=1", "experiment.plots=false", f"hydra.run.dir={tmp_path / 'plain'}",
                       cwd=tmp_path)
    assert plain.returncode == 0, plain.stderr[-3000:]
    run = tmp_path / "sweep"
    rows = list(csv.DictReader((run / "route_following.csv").open()))
    assert len(rows) == 3 * 2 * 3  # the run itself, jitter 0.02, stride 4
    table = list(csv.DictReader((run / "errors_per_route.csv").open()))
    assert [(t["route"], t["seed"]) for t in table] == [("Ant2_Route1", "0"), ("Ant2_Route1", "1")]
    for t in table:
        for agent in ("perfect_memory", "random_choice", "mfdid"):
            (r,) = [r for r in rows if r["agent"] == agent and r["seed"] == t["seed"] and not r["axis"]]
            assert t[agent] == r["errors"] and t[agent].isdigit()
    drawn = plot_errors_per_route(tmp_path / "check.png", table, ["perfect_memory", "random_choice", "mfdid"], title="")
    for agent, values in drawn.items():
        assert sorted(values.tolist()) == sorted(int(t[agent]) for t in table)
    assert (run / "plots" / "errors_per_route.png").stat().st_size > 10_000
    assert (run / "plots" / "robustness_position_jitter_m.png").is_file()
    assert (run / "plots" / "robustness_training_stride.png").is_file()
    summary = list(csv.DictReader((run / "robustness.csv").open()))
    from bionav.experiments.route_homing.plots import plot_robustness

    lines = plot_robustness(tmp_path / "r.png", [s for s in summary if s["axis"] == "training_stride"],
                            axis="training_stride", unit="", agents=["perfect_memory", "random_choice", "mfdid"])
    for agent, (x, med, _nest) in lines.items():
        mine = sorted((s for s in summary if s["axis"] == "training_stride" and s["agent"] == agent),
                      key=lambda s: float(s["level"]))
        assert x.tolist() == [1.0, 4.0] and med.tolist() == [float(s["errors_median"]) for s in mine]
    for s in summary:
        if s["axis"] == "training_stride" and float(s["level"]) == 4:
            mine = [int(r["errors"]) for r in rows if r["axis"] == "training_stride" and r["agent"] == s["agent"]]
        else:
            mine = [int(r["errors"]) for r in rows if not r["axis"] and r["agent"] == s["agent"]] \
                if float(s["level"]) in (0.0, 1.0) else \
                [int(r["errors"]) for r in rows if r["axis"] == s["axis"] and r["agent"] == s["agent"]]
        assert float(s["errors_median"]) == np.median(mine) and int(s["runs"]) == 2
    m = json.loads((run / "metrics.json").read_text())
    assert m["errors_per_route_random_choice"] > m["errors_per_route_perfect_memory"]
    assert m["workers"] == 2
    cells = [[c.strip() for c in line.strip().strip("|").split("|")] for line in sweep.stdout.splitlines()
             if line.startswith("| errors_per_route") or line.startswith("| error_free_routes")]
    printed = {c[0]: c[1] for c in cells}  # | metric | value | metrics.json key |
    assert len(printed) == 3 * 5
    for key, text in printed.items():  # whole counts print as integers ("1", not "1.0000"); means stay floats
        if "_mean_" in key:
            assert isinstance(m[key], float) and float(text) == pytest.approx(m[key], abs=1e-4), (key, text)
        elif float(m[key]).is_integer():
            assert isinstance(m[key], int) and text == str(m[key]), (key, text)
    assert m["sweep"] == {"position_jitter_m": [0.0, 0.02], "training_stride": [1, 4]}
    same = list(csv.DictReader((tmp_path / "plain" / "route_following.csv").open()))
    keys = ("route", "agent", "seed", "errors", "reached_nest", "steps")
    assert [tuple(r[k] for k in keys) for r in same] == [tuple(r[k] for k in keys) for r in rows if not r["axis"]]


# --------------------------------------------------------------------------- the mushroom body's KC thresholds
def test_kenyon_thresholds_are_each_kcs_mean_and_std_with_a_floor_for_constant_kcs():
    """Drives of 3 KCs over 4 training views: KC 0 is 0, 2, 4, 6 (mean 3, std sqrt(5)); KC 1 is constant (std 0:
    gets floor x the median of the positive stds); KC 2 is 1, 1, 1, 5 (mean 2, std sqrt(3))."""
    from bionav.homing.familiarity import kenyon_thresholds

    d = np.array([[0.0, 7.0, 1.0], [2.0, 7.0, 1.0], [4.0, 7.0, 1.0], [6.0, 7.0, 5.0]])
    centre, scale = kenyon_thresholds(d, floor=0.1)
    np.testing.assert_allclose(centre, [3.0, 7.0, 2.0])
    median_sd = (math.sqrt(5.0) + math.sqrt(3.0)) / 2
    np.testing.assert_allclose(scale, [math.sqrt(5.0), 0.1 * median_sd, math.sqrt(3.0)])


def test_per_kc_thresholds_rank_each_kc_against_its_own_training_drive_as_a_plain_loop():
    """The ``n_active`` KCs with the largest ``(drive - mean) / std`` fire, exactly ``n_active`` per view (the
    stated sparsity: 200 of 20,000 = 1 % in the agent), ties going to the lower KC index; written out KC by KC."""
    from bionav.homing.familiarity import kenyon_activity, kenyon_connections, kenyon_matrix, kenyon_thresholds

    rng = np.random.default_rng(4)
    conn = kenyon_connections(16, 40, 3, rng=rng)
    train, test = rng.random((6, 16)), rng.random((5, 16))
    drive_train = np.array([[v[c].sum() for c in conn] for v in train])
    mean = drive_train.mean(0)
    sd = np.sqrt(((drive_train - mean) ** 2).mean(0))
    thr = kenyon_thresholds(drive_train)
    act = kenyon_activity(test, kenyon_matrix(conn, 16), n_active=6, thresholds=thr)
    assert act.shape == (5, 40) and np.all(act.sum(1) == 6)
    for a, v in zip(act, test):
        z = [(v[c].sum() - m) / s for c, m, s in zip(conn, mean, sd)]
        assert set(np.flatnonzero(a)) == set(np.argsort(z)[::-1][:6])
    tied = kenyon_activity(np.zeros((1, 16)), conn, n_active=3)  # every drive 0: KCs 0, 1, 2 fire
    np.testing.assert_array_equal(np.flatnonzero(tied[0]), [0, 1, 2])


def test_per_kc_thresholds_stop_kcs_on_bright_pixels_from_firing_on_every_view():
    """PN 0 is 100 times brighter than the rest on every view. Ranked by raw drive (``kc_threshold=shared``) only
    KCs that sample PN 0 (about 4/20 of the 400) ever fire; ranked against their own training drive (``per_kc``)
    a KC fires when its own inputs are unusually bright, so the firing KCs are drawn from all KCs alike: the
    share of PN-0 KCs among them is near their share of all KCs, and far below 1."""
    from bionav.config import plugin_config
    from bionav.homing.familiarity import kenyon_activity

    rng = np.random.default_rng(1)
    views = rng.random((40, 4, 5)) * 0.1
    views[:, 0, 0] = 10.0  # pixel 0: bright on every view
    share = {}
    for mode in ("shared", "per_kc"):
        cls, config = plugin_config("route_agent", {"name": "mushroom_body", "n_kc": 400, "inputs_per_kc": 4,
                                                    "n_active": 20, "kc_threshold": mode})
        agent = cls(config, rng=np.random.default_rng(2))
        agent.train(views[:30])
        bright = np.asarray(agent.connections[0].todense()).ravel() > 0  # KCs sampling PN 0
        act = kenyon_activity(views[30:].reshape(10, -1), agent.connections, n_active=20, thresholds=agent.thresholds)
        assert np.all(act.sum(1) == 20)
        share[mode] = act[:, bright].sum() / act.sum()
        share["all"] = bright.mean()
    assert share["shared"] == 1.0
    assert 0.1 < share["all"] < 0.3 and share["per_kc"] < 2 * share["all"], share


@pytest.mark.slow
def test_a_split_ardin2016_run_merges_into_the_unsplit_run(tmp_path):
    """experiment.block=[i,2] runs every other group of units (route, seed, condition); python -m
    bionav.experiments.merge joins the two tasks into the files of the unsplit run: the same rows in the same
    order (CPU times aside), the same per-route table, robustness.csv and metrics; a task given twice is refused."""
    import csv
    import json

    from helpers import assert_fails_cleanly, run_bionav

    common = ["experiment=route_homing", "experiment.protocol=ardin2016", "experiment.routes=[Ant2_Route1]",
              "experiment.agents=[perfect_memory,random_choice]", "+experiment.sweep.heading_noise_deg=[0,20]",
              "+experiment.sweep.training_stride=[1,4]", f"cache_dir={tmp_path / 'cache'}"]
    for name, extra in (("whole", []), ("t0", ["experiment.block=[0,2]"]), ("t1", ["experiment.block=[1,2]"])):
        proc = run_bionav(*common, *extra, f"hydra.run.dir={tmp_path / name}", cwd=tmp_path)
        assert proc.returncode == 0, proc.stderr[-3000:]
    t0 = list(csv.DictReader((tmp_path / "t0" / "route_following.csv").open()))
    assert [r["unit"] for r in t0] == ["0", "1", "4", "5"]  # groups 0 and 2 of 3 (the run, heading noise 20, stride 4)
    proc = run_bionav(str(tmp_path / "merged"), str(tmp_path / "t1"), str(tmp_path / "t0"),
                      module="bionav.experiments.merge", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "merged 2 route_homing tasks" in proc.stdout

    def table(run, name, drop=("cpu_s", "views_cpu_s", "cpu_s_per_route")):
        return [{k: v for k, v in r.items() if k not in drop} for r in csv.DictReader((tmp_path / run / name).open())]

    for name in ("route_following.csv", "errors_per_route.csv", "robustness.csv"):
        assert table("merged", name) == table("whole", name), name
    whole = json.loads((tmp_path / "whole" / "metrics.json").read_text())
    merged = json.loads((tmp_path / "merged" / "metrics.json").read_text())
    for key in ("errors_per_route_perfect_memory", "errors_by_route_random_choice", "sweep", "n_conditions"):
        assert merged[key] == whole[key], key
    assert (tmp_path / "merged" / "plots" / "robustness_training_stride.png").is_file()
    assert (tmp_path / "merged" / "plots" / "world_routes.png").is_file()
    proc = run_bionav(str(tmp_path / "again"), str(tmp_path / "t0"), str(tmp_path / "t0"),
                      module="bionav.experiments.merge", cwd=tmp_path)
    assert_fails_cleanly(proc, "block")


@pytest.mark.parametrize("args, needles", [
    (["experiment.protocol=ardin2016", "experiment.block=[3,2]"], ("experiment.block", "0 <= i < n")),
    (["experiment.protocol=ardin2016", "experiment.block=[1,2]"], ("selects no group of units", "at most 1 tasks")),
    (["experiment.block=[0,2]"], ("experiment.protocol=ardin2016",)),
])
def test_a_bad_block_is_one_clear_message(tmp_path, args, needles):
    from helpers import assert_fails_cleanly, run_bionav

    proc = run_bionav("experiment=route_homing", "experiment.routes=[Ant2_Route1]", "experiment.agents=[random_choice]",
                      *args, f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, *needles)
