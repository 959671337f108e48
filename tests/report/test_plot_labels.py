"""The plots issue 32 names: labelled axes with units, whole-cell ticks on grid maps, legends covering no data."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from bionav.report.figures import pyplot


@pytest.fixture
def figures(monkeypatch):
    """The figures a plot function made (pyplot.close disabled while the test runs)."""
    plt = pyplot()
    plt.close("all")
    monkeypatch.setattr(plt, "close", lambda *a, **k: None)

    def made():
        return [plt.figure(n) for n in plt.get_fignums()]

    yield made
    monkeypatch.undo()
    plt.close("all")


def _legend_clear_of_axes(fig, ax) -> bool:
    r = fig.canvas.get_renderer()
    legend = ax.get_legend() or (fig.legends[0] if fig.legends else None)
    assert legend is not None
    return not legend.get_window_extent(r).overlaps(ax.get_window_extent(r))


def _whole_cell_ticks(ax) -> None:
    for axis, lim in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        ticks = [t for t in axis.get_majorticklocs() if min(lim) <= t <= max(lim)]
        assert ticks and all(float(t).is_integer() for t in ticks), ticks


def test_per_snapshot_maps_have_whole_cell_ticks_and_named_axes(tmp_path, figures):
    from bionav.experiments.grid_homing.plots import plot_home_vector_field, plot_per_snapshot_maps

    pos = np.array([[0, 0], [3, 1], [2, 2]])  # a 4 x 3 grid: matplotlib alone would tick every half cell
    plot_per_snapshot_maps(tmp_path / "p.png", positions=pos, grid_shape=(4, 3), aae_s=np.array([0.1, 0.2, 0.3]),
                           rr_s=np.array([1.0, 0.5, 0.0]), title="t")
    plot_home_vector_field(tmp_path / "h.png", positions=pos, angles=np.zeros(3), snapshot=pos[0], grid_shape=(4, 3),
                           title="t")
    maps, field = figures()
    for ax in [*maps.axes[:2], field.axes[0]]:  # maps: two heatmaps, then their colour bars
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (grid cells)", "y (grid cells)")
        _whole_cell_ticks(ax)
    # AAE_s is capped at pi/2: its colour bar says what the overflow colour means (issue 45)
    assert [c.get_ylabel() for c in maps.axes[2:]] == ["AAE$_s$ (rad), cyan > 1.57", "RR$_s$"]


def test_home_vector_field_legend_names_every_colour_and_marker(tmp_path, figures):
    """Issue 45: the red (failed) arrows, the crosses of cells without a direction, the agents' paths and the
    snapshot star each have a legend entry, and the AAE map draws errors above pi/2 in the named over colour."""
    from matplotlib.colors import to_rgba

    from bionav.experiments.grid_homing.plots import plot_home_vector_field, plot_per_snapshot_maps

    pos = np.array([[0, 0], [1, 0], [0, 1], [1, 1]])
    plot_home_vector_field(tmp_path / "h.png", positions=pos, angles=np.array([np.nan, 0.5, 1.0, 2.0]),
                           snapshot=pos[0], grid_shape=(2, 2), title="t", success=np.array([False, True, False, True]),
                           paths=[np.array([[1.0, 0.0], [0.5, 0.0]])])
    plot_per_snapshot_maps(tmp_path / "p.png", positions=pos, grid_shape=(2, 2), aae_s=np.array([0.1, 2.5, 0.3, 3.0]),
                           rr_s=np.array([1.0, 0.0, 0.5, 0.0]), title="t")
    field, maps = figures()
    legend = next(ax.get_legend() for ax in field.axes if ax.get_legend() is not None)
    labels = [t.get_text() for t in legend.get_texts()]
    assert labels == ["home vector (its return agent reached the snapshot)", "home vector (its return agent failed)",
                      "no direction given", "return agents' paths", "snapshot position"]
    colours = [to_rgba(h.get_color()) for h in legend.legend_handles[:2]]
    arrows = field.axes[0].collections[0].get_facecolors()
    assert {tuple(c) for c in arrows} == {tuple(colours[0]), tuple(colours[1])}  # blue and red, both named
    image = maps.axes[0].get_images()[0]
    assert to_rgba(image.get_cmap().get_over()) == to_rgba("tab:cyan")
    assert maps.axes[2].get_ylabel() == "AAE$_s$ (rad), cyan > 1.57"


def test_world_routes_legend_names_every_line_and_the_title_matches(tmp_path, figures):
    from bionav.experiments.route_homing.plots import ROUTE_COLOR, plot_world_routes

    tri = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
    world = SimpleNamespace(mesh=SimpleNamespace(triangles=tri), extent=lambda: ((0.0, 0.0), (4.0, 4.0)))
    line = np.c_[np.linspace(0.5, 3.5, 20), np.linspace(0.5, 3.0, 20)]
    setup = SimpleNamespace(name="r1", dense_xy=line, xy=line[::4])
    plot_world_routes(tmp_path / "w.png", world, [setup], {("r1", "windowed"): line + 0.1, ("r1", "homing"): None})
    (fig,) = figures()
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["recorded route", "route snapshots", "agent path: windowed"]
    drawn = ax.get_lines()
    assert [ln.get_label() for ln in drawn] == labels  # every line drawn has its legend entry
    route = next(ln for ln in drawn if ln.get_label() == "recorded route")
    assert route.get_color() == ROUTE_COLOR and "(grey)" in ax.get_title()
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (m)", "y (m)")
    assert _legend_clear_of_axes(fig, ax)


def test_session_errors_floor_whiskers_and_caption(tmp_path, figures):
    from bionav.experiments.pol_recordings.plots import ERROR_FLOOR_DEG, session_distributions

    err = np.radians(np.r_[1e-4, np.linspace(0.5, 20.0, 99)])  # one error of 1e-4 deg, as the issue saw
    s = SimpleNamespace(day="2025-06-01", time_of_day="noon")
    session_distributions(tmp_path / "s.png", [(s, SimpleNamespace(period="daylight"), err)], "sky_fit")
    (fig,) = figures()
    ax = fig.axes[0]
    assert ax.get_ylim()[0] == pytest.approx(ERROR_FLOOR_DEG) and ax.get_yscale() == "log"
    clipped = np.maximum(np.degrees(err), ERROR_FLOOR_DEG)
    ends = sorted({y for ln in ax.get_lines() for y in ln.get_ydata()})
    lo, hi = np.percentile(clipped, [5, 95])  # matplotlib ends a whisker at the last datum inside its percentile
    assert min(ends) == pytest.approx(clipped[clipped >= lo].min()) and max(ends) == pytest.approx(clipped[clipped <= hi].max())
    assert "5th-95th percentile" in ax.get_title() and "deg" in ax.get_ylabel()
    assert ax.get_xlabel().startswith("session")


def test_compass_plots_axes_and_legends(tmp_path, figures):
    from bionav.experiments.pol_compass.plots import plot_rotation, plot_unit_voltages

    pans = np.radians(np.linspace(-160, 160, 33))
    plot_rotation(tmp_path / "r.png", pans, pans + 0.01, np.full(33, 0.01), axial=True)
    angle = np.linspace(0, 180, 19)
    volts = np.stack([np.cos(np.radians(2 * (angle - 60 * k))) for k in range(3)], axis=1)
    plot_unit_voltages(tmp_path / "u.png", angle, volts, xlabel="filter angle (deg)")
    rot, units = figures()
    top, bottom = rot.axes
    assert "mod 180" not in top.get_ylabel() and top.get_ylabel() == "heading (deg, CCW)"
    assert any("nearest the pan" in t.get_text() for t in top.get_legend().get_texts())
    assert bottom.get_xlabel() == "pan (deg, CCW)" and "(deg" in bottom.get_ylabel()
    assert _legend_clear_of_axes(rot, top)
    ax = units.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("filter angle (deg)", "output voltage (V)")
    assert _legend_clear_of_axes(units, ax)


def test_thesis_bar_charts_have_a_y_label_and_a_legend_beside_the_bars(tmp_path, figures):
    from bionav.thesis.items import compare_bars

    with pytest.raises(TypeError):
        compare_bars(tmp_path / "x.png", ["a"], {"thesis": [1.0]}, title="t")  # no y label: refused
    compare_bars(tmp_path / "t.png", ["AAE* original", "RR* original"], {"thesis": [0.27, 0.96], "bionav": [0.3, 0.9]},
                 title="Table 5.3", ylabel="AAE* (rad) | RR* (fraction of agents home)")
    (fig,) = figures()
    assert fig.axes[0].get_ylabel() == "AAE* (rad) | RR* (fraction of agents home)"
    assert _legend_clear_of_axes(fig, fig.axes[0])


@pytest.mark.usefixtures("controllers")
def test_cleaning_legends_stand_beside_or_below_the_maps(tmp_path, figures):
    from helpers import cleaning_config as config

    from bionav.experiments.runner import run_experiment

    run_experiment(config("odometry"), tmp_path, show_progress=False)
    by_title = {f.axes[0].get_title(): f for f in figures() if f.axes}
    traj = next(f for t, f in by_title.items() if t.startswith("Trajectories"))
    layout = next(f for t, f in by_title.items() if t.startswith("Layout in the world"))
    for fig in (traj, layout):
        ax = fig.axes[0]
        assert ax.get_xlabel().endswith("(m)") and ax.get_ylabel().endswith("(m)")
        assert _legend_clear_of_axes(fig, ax)
    labels = [t.get_text() for t in traj.axes[0].get_legend().get_texts()]
    assert labels[:3] == ["obstacle outlines", "target area", "ideal meander"] and len(labels) == 3 + 2  # 2 runs


def test_sweep_figure_draws_the_metric_over_the_swept_values(tmp_path):
    """summary.png of a sweep (issue 45): one panel per metric (AAE*, RR*), x the first swept key, one series per
    value of the others, failed jobs left out and counted."""
    from bionav.report.sweep_figure import plot_sweep

    rows = [{"job": "0", "homing": "sift", "db": "a", "status": "completed", "aae": 0.5, "rr": 0.9},
            {"job": "1", "homing": "mfdid", "db": "a", "status": "completed", "aae": 0.8, "rr": 0.6},
            {"job": "2", "homing": "sift", "db": "b", "status": "completed", "aae": 0.4, "rr": 0.95},
            {"job": "3", "homing": "mfdid", "db": "b", "status": "failed", "error": "x"}]
    captured = {}
    import matplotlib.figure

    original = matplotlib.figure.Figure.savefig

    def keep(fig, *args, **kwargs):
        captured["fig"] = fig
        return original(fig, *args, **kwargs)

    matplotlib.figure.Figure.savefig = keep
    try:
        path = plot_sweep(tmp_path, rows, ["homing", "db"])
    finally:
        matplotlib.figure.Figure.savefig = original
    assert path == tmp_path / "summary.png" and path.stat().st_size > 0
    fig = captured["fig"]
    aae_ax, rr_ax = fig.axes[:2]
    assert aae_ax.get_xlabel() == "homing" and aae_ax.get_ylabel() == "AAE* (rad)"
    assert rr_ax.get_ylabel() == "RR* (fraction of agents home)"
    series = {line.get_label(): list(line.get_ydata()) for line in aae_ax.get_lines()}
    assert series == {"db=a": [0.5, 0.8], "db=b": [0.4]}  # x positions: sift 0, mfdid 1; the failed job not drawn
    assert "1 failed (not drawn)" in fig._suptitle.get_text()
    assert plot_sweep(tmp_path, rows[:1], ["homing"]) is None  # nothing varies
