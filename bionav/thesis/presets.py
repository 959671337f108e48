"""Presets of ``python -m bionav.thesis``: how much of each thesis experiment to run.

``full`` uses the thesis' own sizes and counts. ``quick`` runs every item on
reduced inputs (snapshot subsets, fewer runs, reduced sweeps; every reduction is
listed in the report) within about 20 minutes on two cores. ``tiny`` exists for
the tests: the whole code path on the smallest inputs that still run.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

#: the eight variants of the original database (thesis 3.1, fig. 5.6)
CROSS_DB_FAMILY = ("sim_original", "sim_arboreal", "sim_chairs", "sim_day", "sim_doorlit", "sim_screen",
                   "sim_twilight", "sim_winlit")
#: fig. 5.4: 0.03 ... 0.1 in steps of 0.01, then 0.2 ... 1.0 in steps of 0.1
THESIS_CUTOFFS = tuple(round(0.03 + 0.01 * i, 2) for i in range(8)) + tuple(round(0.2 + 0.1 * i, 1) for i in range(9))
DAY_SERIES = 14
#: the one-day series' scan grid (thesis 6.4.1: pan in 1-degree steps over 200 degrees, tilt in 2-degree steps
#: over 102 degrees, 40 minutes per scan); experiment=contrast_scan's defaults are the example data sets' grid
ONE_DAY_SCAN = {"experiment.n_pan": 200, "experiment.pan_step_deg": 1.0, "experiment.n_tilt": 51,
                "experiment.tilt_step_deg": 2.0, "experiment.scan_minutes": 40.0}


@dataclass(frozen=True)
class Preset:
    """Sizes and counts of one preset (see the module docstring).

    ``snapshots``: snapshots per grid-homing run, spread evenly over the
    database's images (None: every image is a snapshot, as the thesis).
    Image sizes are ``(W, H)`` in pixels.
    """

    name: str
    summary: str
    snapshots: int | None
    sift_size: tuple[int, int]
    warping: tuple[str, ...]
    warping_snapshots: int | None
    warping_size: tuple[int, int] | None
    fig54_sizes: tuple[tuple[int, int], ...]
    fig54_cutoffs: tuple[float, ...]
    fig55_sizes: tuple[tuple[int, int], ...]
    b_sizes: tuple[tuple[int, int], ...]
    cross_db_family: tuple[str, ...]
    cross_db_stride: int
    cross_db_size: tuple[int, int] | None
    cross_db_homing: tuple[str, ...]
    param_grid: str
    lda_resamples: int
    scan: dict = field(default_factory=dict)
    scan_times: int = DAY_SERIES
    example_scan: dict = field(default_factory=dict)
    skyline: tuple[str, ...] = ()
    pol_samples: int = 100
    pol_vs_em_samples: int = 100
    cleaning_runs: int = 10
    #: ``db.pose_error.seed`` values of the table 5.3 runs: each stand-in is measured once per draw of
    #: the capture session (pose errors, floor tilts, clouds) and the mean is compared with the thesis
    #: (empty: one run with the config's draw)
    pose_draws: tuple[int, ...] = ()
    #: tasks per grid-homing run by homing method (``experiment.block``; missing: 1): a run of all
    #: snapshots with the thesis' warping parameters needs about 16 CPU hours (docs/thesis.md), so it
    #: goes as 64 tasks of about 15 minutes each that a launcher spreads over cores and nodes
    grid_blocks: dict = field(default_factory=dict)
    #: tasks per cross-database run (fig. 5.6) by homing method: the thesis' 2D-warping over all 8 x 8
    #: database pairs needs about 50 CPU hours (plan of 2026-11-27), so 128 tasks of two snapshots each
    cross_db_blocks: dict = field(default_factory=dict)
    reductions: tuple[str, ...] = ()


FULL = Preset(
    name="full",
    summary="the thesis' own sizes and counts",
    snapshots=None,
    sift_size=(1122, 162),
    warping=("warping2d_thesis", "minwarping_thesis"),
    warping_snapshots=None,
    warping_size=None,
    fig54_sizes=((346, 50), (561, 81), (1122, 162)),
    fig54_cutoffs=THESIS_CUTOFFS,
    fig55_sizes=((346, 50), (561, 81), (1122, 162)),
    b_sizes=((1672, 206), (836, 103), (418, 52), (209, 52)),
    cross_db_family=CROSS_DB_FAMILY,
    cross_db_stride=1,
    cross_db_size=(1122, 162),  # thesis 5.3: SIFT at 1122 x 162; warping2d_thesis resizes to its 346 x 50 itself
    cross_db_homing=("sift", "warping2d_thesis"),
    param_grid="full",
    lda_resamples=10000,
    scan=ONE_DAY_SCAN,
    scan_times=DAY_SERIES,
    example_scan={},
    skyline=(),
    pol_samples=100,
    pol_vs_em_samples=100,
    cleaning_runs=10,
    grid_blocks={"warping2d_thesis": 64, "minwarping_thesis": 64, "sift": 8},
    cross_db_blocks={"warping2d_thesis": 128, "sift": 16},
    reductions=(),
)

QUICK = Preset(
    name="quick",
    summary="every item on reduced inputs (about 20 minutes on two idle cores)",
    snapshots=6,
    sift_size=(561, 81),
    warping=("warping2d", "minwarping"),
    warping_snapshots=2,
    warping_size=None,
    fig54_sizes=((346, 50), (561, 81)),
    fig54_cutoffs=(0.05, 0.1, 0.3, 1.0),
    fig55_sizes=((346, 50), (561, 81)),
    b_sizes=((418, 52), (209, 52)),
    cross_db_family=("sim_original", "sim_arboreal", "sim_chairs", "sim_doorlit", "sim_screen", "sim_winlit"),
    cross_db_stride=9,
    cross_db_size=(346, 50),
    cross_db_homing=("sift", "warping2d"),
    param_grid="ci",
    lda_resamples=1000,
    scan={"experiment.n_pan": 38, "experiment.pan_step_deg": 6.0, "experiment.n_tilt": 9,
          "experiment.tilt_step_deg": 9.0},
    scan_times=DAY_SERIES,
    example_scan={"experiment.n_pan": 57, "experiment.pan_step_deg": 4.0, "experiment.n_tilt": 13,
                  "experiment.tilt_step_deg": 6.0},
    skyline=("experiment.snapshot_stride=4",),
    pol_samples=100,
    pol_vs_em_samples=100,
    cleaning_runs=2,
    cross_db_blocks={"warping2d": 16},
    reductions=(
        "grid homing: 6 snapshots per database (evenly spread over the images) instead of all; "
        "min-/2D-warping: 2 snapshots",
        "SIFT homing (table 5.3, fig. 5.6) at the stand-ins' native 561 x 81 instead of 1122 x 162",
        "table 5.4: the fast warping presets (homing=warping2d, homing=minwarping) instead of the thesis' "
        "parameters (warping2d_thesis, minwarping_thesis)",
        "fig. 5.4: cutoffs 0.05, 0.1, 0.3, 1.0 at 346 x 50 and 561 x 81 (thesis: 17 cutoffs, three sizes)",
        "fig. 5.5: 346 x 50 and 561 x 81 (thesis: also 1122 x 162)",
        "appendix B: 418 x 52 and 209 x 52 (thesis: also 1672 x 206 and 836 x 103)",
        "fig. 5.6: six of the eight databases (no day, twilight), 4 snapshots per database (stride 9), "
        "images 346 x 50, the fast 2D-warping preset",
        "tables 5.5-5.7: the reduced parameter grid experiment.grid=ci (one image size, no preprocessing, "
        "two ring counts and two Fourier-coefficient counts; thesis: 5202 configurations per database)",
        "tables 6.3/6.5: 1000 bootstrap resamples (thesis: 10000)",
        "figs. 6.10-6.15: scans of 38 x 9 points (6 and 9 degree steps, 20 minutes) instead of 200 x 51 "
        "(1 and 2 degree steps, 40 minutes); "
        "figs. 6.16-6.25: 57 x 13 points instead of 113 x 26",
        "figs. 6.26/6.27: the skyline-homing grid with snapshot stride 4 (the square test itself is complete)",
        "figs. 7.3/7.4: 2 cleaning runs per layout (thesis: 10)",
    ),
)

TINY = Preset(
    name="tiny",
    summary="the smallest inputs that run the whole code path (for tests; numbers mean nothing)",
    snapshots=2,
    sift_size=(120, 18),
    warping=("warping2d",),
    warping_snapshots=1,
    warping_size=(120, 18),
    fig54_sizes=((120, 18),),
    fig54_cutoffs=(0.3, 1.0),
    fig55_sizes=((120, 18),),
    b_sizes=((120, 18),),
    cross_db_family=("sim_original", "sim_doorlit"),
    cross_db_stride=9,
    cross_db_size=(120, 18),
    cross_db_homing=("sift",),
    param_grid="ci",
    lda_resamples=50,
    scan={"experiment.n_pan": 12, "experiment.pan_step_deg": 15.0, "experiment.n_tilt": 5,
          "experiment.tilt_step_deg": 15.0},
    scan_times=3,
    example_scan={"experiment.n_pan": 12, "experiment.pan_step_deg": 15.0, "experiment.n_tilt": 5,
                  "experiment.tilt_step_deg": 15.0},
    skyline=("experiment.snapshot_stride=8",),
    pol_samples=2,
    pol_vs_em_samples=2,
    cleaning_runs=1,
    reductions=("tiny preset: every size and count reduced to a minimum; for tests only",),
)

#: the checks of issue 18 (``--only standins``): SIFT homing at the thesis' 1122 x 162 on snapshot subsets,
#: the thesis' warping parameters on hall1, the doorlit/winlit cross test, the reduced parameter grid
STANDINS = dataclasses.replace(
    QUICK,
    name="standins",
    summary=("the stand-in hardness checks of issue 18 (about 4 minutes on two idle cores once the stand-ins "
             "are in the render cache; the first run renders them)"),
    snapshots=12,
    sift_size=(1122, 162),
    warping=("warping2d_thesis", "minwarping_thesis"),
    warping_snapshots=3,
    cross_db_family=("sim_doorlit", "sim_winlit"),
    cross_db_stride=9,
    cross_db_size=None,
    cross_db_homing=("sift", "warping2d"),
    pose_draws=(0, 1, 2),
    reductions=(
        "SIFT homing (table 5.3): 12 snapshots per database (evenly spread over the images) instead of all, "
        "every image a current view; 1122 x 162 as the thesis; each database measured on 3 draws of the "
        "capture session (db.pose_error.seed=0,1,2: pose errors, floor tilts, clouds), compared by the mean",
        "table 5.4: the thesis' parameters (warping2d_thesis, minwarping_thesis), 3 snapshots per database; "
        "the stand-in check compares them with SIFT on hall1 on the 12 snapshots and 3 draws of table 5.3",
        "fig. 5.6: doorlit and winlit only, 4 snapshots per database (stride 9), SIFT homing at the native "
        "561 x 81, the fast 2D-warping preset (homing=warping2d)",
        "tables 5.5-5.7: the reduced parameter grid experiment.grid=ci (one image size, no preprocessing, "
        "two ring counts and two Fourier-coefficient counts; thesis: 5202 configurations per database)",
    ),
)

#: the quick preset with the thesis' sizes and counts where the quick reduction could decide a verdict (issue 44,
#: docs/thesis.md "Why"): appendix B's four image sizes, fig. 5.4's 17 cutoffs, the one-day scans' grid, 10,000
#: bootstrap resamples,
#: fig. 5.6's SIFT homing on all eight databases at the thesis' 1122 x 162 (its 2D-warping claims hold in quick)
DIAGNOSE = dataclasses.replace(
    QUICK,
    name="diagnose",
    summary="quick with the thesis' sizes where the reduction could decide a verdict (issue 44)",
    b_sizes=FULL.b_sizes,
    fig54_cutoffs=THESIS_CUTOFFS,
    lda_resamples=FULL.lda_resamples,
    scan=ONE_DAY_SCAN,
    cross_db_family=CROSS_DB_FAMILY,
    cross_db_size=(1122, 162),
    cross_db_homing=("sift",),
    cross_db_blocks={"sift": 4},
    reductions=(
        "grid homing: 6 snapshots per database (evenly spread over the images) instead of all (as quick); "
        "appendix B at the thesis' four image sizes; fig. 5.4 at the thesis' 17 cutoffs (346 x 50 and 561 x 81)",
        "fig. 5.6: SIFT homing only, on all eight databases at the thesis' 1122 x 162, 4 snapshots per database "
        "(stride 9, as quick)",
        "figs. 6.10-6.15: the thesis' one-day grid (200 x 51 points, 1 and 2 degree steps, 40 minutes per scan)",
        "tables 6.3/6.5: 10000 bootstrap resamples, as the thesis",
        "every other item as the quick preset",
    ),
)

PRESETS = {p.name: p for p in (QUICK, FULL, TINY, STANDINS, DIAGNOSE)}
#: presets offered by ``--help`` (tiny: the whole report in minutes, numbers that mean nothing; the tests use it)
PUBLIC_PRESETS = ("quick", "full", "standins", "diagnose", "tiny")
