"""Figures of ``experiment=pol_recordings``."""

from __future__ import annotations

import numpy as np

from bionav.report.figures import pyplot, save_figure

DPI = 110


def _hours(hhmm: str) -> float:
    h, m = hhmm.split(":")
    return int(h) + int(m) / 60.0


def error_vs_time_of_day(path, session_rows, decoders) -> None:
    """MAE per session against local time of day, one line per decoder; sun elevation on a second axis."""
    plt = pyplot()
    fig, ax = plt.subplots(1, 2, figsize=(11, 4), sharey=True, gridspec_kw={"width_ratios": [3, 1]})
    tod = [r for r in session_rows if r["condition"] == "tod" and r["time_of_day"]]
    canopy = [r for r in session_rows if r["condition"] == "canopy" and r["time_of_day"]]
    for d in decoders:
        for axis, rows in ((ax[0], tod), (ax[1], canopy)):
            pts = sorted((_hours(r["time_of_day"]), r["mae_deg"], r["day"]) for r in rows if r["decoder"] == d)
            if pts:
                axis.plot([p[0] for p in pts], [p[1] for p in pts], "o", ms=4, label=d if axis is ax[0] else None)
    ax[0].set_yscale("log")
    ax[0].set_xlabel("local time (h)")
    ax[0].set_ylabel("MAE (deg)")
    ax[0].set_title("time-of-day sessions")
    ax[1].set_title("canopy sessions")
    ax[1].set_xlabel("local time (h)")
    twin = ax[0].twinx()
    el = sorted({(_hours(r["time_of_day"]), r["sun_elevation_deg"]) for r in tod})
    if el:
        twin.plot([e[0] for e in el], [e[1] for e in el], "k+", ms=5, alpha=0.6)
    twin.set_ylabel("sun elevation (deg), black crosses")
    ax[0].legend(fontsize=7, ncol=2)
    save_figure(fig, path, dpi=DPI)


#: lower end of the log axis of session_errors.png (deg); smaller errors are drawn at it
ERROR_FLOOR_DEG = 0.1


def session_distributions(path, per_session, decoder) -> None:
    """Box plot of absolute heading errors per session (chosen decoder), degrees on a log axis.

    Boxes span the quartiles with the median as a line; whiskers reach the
    5th and 95th percentiles (outliers are not drawn). The log axis starts at
    :data:`ERROR_FLOOR_DEG`: a decoded heading can hit the recorded yaw to a
    thousandth of a degree by chance, which says nothing, so errors below the
    floor are drawn at it (the plot's caption says so).
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(max(6, 0.35 * len(per_session) + 2), 4.4))
    data = [np.maximum(np.abs(np.degrees(err)), ERROR_FLOOR_DEG) for _s, _d, err, *_ in per_session]
    labels = [f"{s.day[5:]} {s.time_of_day}{' C' if d.period == 'canopy' else ''}" for s, d, *_ in per_session]
    ax.boxplot(data, whis=(5, 95), showfliers=False)
    ax.set_xticks(range(1, len(labels) + 1))
    ax.set_xticklabels(labels, rotation=90, fontsize=7)
    ax.set_yscale("log")
    ax.set_ylim(bottom=ERROR_FLOOR_DEG)
    ax.set_xlabel("session (month-day, time of day; C: under canopy)")
    ax.set_ylabel(f"|heading error| (deg, log; < {ERROR_FLOOR_DEG:g} at {ERROR_FLOOR_DEG:g})")
    ax.set_title(f"per-session error distributions, decoder={decoder}\n"
                 "box: quartiles and median; whiskers: 5th-95th percentile", fontsize=9)
    save_figure(fig, path, dpi=DPI)


def raw_rotation(path, session, data) -> None:
    """The four photodiode counts of every unit during the session's first rotation."""
    plt = pyplot()
    sel = data.rotation_index == 0
    yaw = np.degrees(np.unwrap(data.yaw[sel]))
    k = data.counts.shape[1]
    fig, axes = plt.subplots(2, (k + 1) // 2, figsize=(12, 5), sharex=True)
    for u, ax in enumerate(np.ravel(axes)[:k]):
        for p in range(data.counts.shape[2]):
            ax.plot(yaw, data.counts[sel, u, p], lw=0.8, label=f"pd {p}")
        tag = " (excluded)" if u in data.excluded else ""
        ax.set_title(f"unit {u}{tag}", fontsize=8)
        ax.tick_params(labelsize=7)
    np.ravel(axes)[0].legend(fontsize=6)
    fig.suptitle(f"raw counts, {session.name}, rotation 1 (x: yaw, deg)", fontsize=9)
    save_figure(fig, path, dpi=DPI)


def clear_vs_canopy(path, errors_by_group, decoder) -> None:
    """Error histograms: time-of-day daylight vs canopy (chosen decoder)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    bins = np.linspace(0, 45, 46)
    for g, label in (("tod_daylight", "clear (tod, daylight)"), ("canopy", "canopy")):
        if errors_by_group.get(g):
            e = np.abs(np.degrees(np.concatenate(errors_by_group[g])))
            ax.hist(np.minimum(e, 45), bins=bins, density=True, alpha=0.5, label=f"{label}: MAE {e.mean():.1f} deg")
    ax.set_xlabel("|error| (deg, clipped at 45)")
    ax.set_ylabel("density")
    ax.set_title(f"clear vs canopy, decoder={decoder}")
    ax.legend(fontsize=8)
    save_figure(fig, path, dpi=DPI)


def sim_vs_real(path, real, sim, decoder) -> None:
    """Cumulative error distributions, real vs simulated, per condition."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    for g, color in (("tod_daylight", "C0"), ("tod_dusk", "C1"), ("canopy", "C2")):
        for src, style, name in ((real, "-", "real"), (sim, "--", "sim")):
            if src.get(g):
                e = np.sort(np.abs(np.degrees(np.concatenate(src[g]))))
                ax.plot(e, np.arange(1, e.size + 1) / e.size, style, color=color, label=f"{g} {name} (MAE {e.mean():.1f})")
    ax.set_xscale("log")
    ax.set_xlim(0.1, 180)
    ax.set_xlabel("|error| (deg)")
    ax.set_ylabel("fraction of samples")
    ax.set_title(f"sim-to-real gap, decoder={decoder}")
    ax.legend(fontsize=7)
    save_figure(fig, path, dpi=DPI)


def yaw_reference(path, per_session, decoder, reference: str) -> None:
    """Per-rotation circular mean of the scored heading error over decoded samples (chosen decoder), sessions in a row.

    Each run of the logged yaw is its own line; red dotted lines mark the rotations whose logged yaw restarts
    (:func:`bionav.polcompass.recordings.yaw_restarts`): steps of the mean there are the
    yaw reference moving, not the decoder (docs/polcompass.md, "The reference").
    """
    from bionav.polcompass.sessions import circular_offset, yaw_runs

    plt = pyplot()
    n_rot = sum(int(d.rotation_index.max()) + 1 for _s, d, *_ in per_session)
    fig, ax = plt.subplots(figsize=(max(6.0, 0.05 * n_rot + 2.0), 4.0))
    x0 = 0
    for i, (_s, d, err, decoded) in enumerate(per_session):
        r = int(d.rotation_index.max()) + 1
        runs = yaw_runs(d)
        means = []
        for j in range(r):
            e = err[(d.rotation_index == j) & decoded]  # undecoded samples (scored 90 degrees) left out
            means.append(np.degrees(circular_offset(e, 0.0)) if e.size else np.nan)
        run_of = np.array([runs[d.rotation_index == j][0] for j in range(r)])
        for run in np.unique(run_of):  # one line per run of the yaw: a step between lines is the reference moving
            js = np.flatnonzero(run_of == run)
            ax.plot(x0 + js, np.asarray(means)[js], ".-", color="C0" if i % 2 == 0 else "C1", lw=0.9, ms=3)
        for j in np.flatnonzero(np.diff(run_of)) + 1:
            ax.axvline(x0 + j - 0.5, color="C3", lw=0.6, ls=":")
        x0 += r + 1
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("rotation (sessions one after another, alternating colours)")
    ax.set_ylabel("mean heading error of the rotation (deg)")
    ax.set_title(f"per-rotation mean error, decoder={decoder}, recordings.reference={reference}\n"
                 "one line per run of the logged yaw; red dotted: the yaw restarts (odometry restart)", fontsize=9)
    save_figure(fig, path, dpi=DPI)
