"""Figures of ``experiment=pol_compass`` (thesis figs. 4.2, 4.4-4.6 and the partial-sky curve)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bionav.report.figures import pyplot, save_figure

UNIT_COLORS = ("tab:blue", "tab:green", "tab:red")  # the thesis' colours for POL-OP units 1-3


def _figure(*args, **kwargs):
    plt = pyplot()
    return plt, *plt.subplots(*args, **kwargs)


def plot_unit_voltages(path: Path, angle_deg, mean_volts, *, xlabel: str) -> None:
    """Mean output voltage of each POL-OP unit against an angle (fig. 4.2)."""
    plt, fig, ax = _figure(figsize=(8, 4))
    order = np.argsort(angle_deg)
    for k in range(mean_volts.shape[1]):
        ax.plot(np.asarray(angle_deg)[order], mean_volts[order, k], ".-", color=UNIT_COLORS[k % 3], label=f"POL-OP unit {k + 1}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("output voltage (V)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)  # beside the axes, covering no curve
    ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=120)


def plot_rotation(path: Path, pans, heading, errors, *, axial: bool, xlabel: str = "pan (deg, CCW)") -> None:
    """Compass heading (offset removed) and its error against the pan angle.

    Headings are plotted in the pan angle's range: an axial compass (which
    cannot tell ``phi`` from ``phi + 180`` deg) is shown as whichever of the two
    lies nearest the pan angle, a full compass as ``phi + k 360`` nearest it.
    Angles in degrees, counter-clockwise.
    """
    plt, fig, (ax1, ax2) = _figure(2, 1, figsize=(8, 6), sharex=True)
    pan_deg = np.degrees(pans)
    period = 180.0 if axial else 360.0
    wrapped = (np.degrees(heading) - pan_deg + period / 2) % period - period / 2 + pan_deg
    ax1.plot(pan_deg, wrapped, ".", ms=3, label="polarized-light compass" + (
        "\n(axial: of phi and phi + 180\nthe one nearest the pan)" if axial else ""))
    ax1.plot(pan_deg, pan_deg, "r-", lw=1, label=xlabel.split(" (")[0])
    ax1.set_ylabel("heading (deg, CCW)")
    ax1.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize=8)
    ax2.plot(pan_deg, np.degrees(errors), ".", ms=3)
    ax2.set_xlabel(xlabel)
    ax2.set_ylabel("heading error (deg)" + (", axial" if axial else ""))
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=120)


def displayed_heading_deg(pol, tcm2, *, nearest: bool) -> np.ndarray:
    """Polarized-light compass headings as figs. 4.4/4.5 show them, degrees.

    Parameters
    ----------
    pol : ndarray
        Compass headings, radians: the first candidate of eq. 4.6 (the other is
        this plus pi).
    tcm2 : ndarray
        Electromagnetic compass headings, radians.
    nearest : bool
        True: show the candidate nearest the TCM2 (an axial comparison);
        False: the raw first candidate wrapped to [-180, 180), which jumps by
        180 degrees against the TCM2 as the thesis' fig. 4.5 does (the compass
        cannot tell 0 from 180 degrees).
    """
    pol_deg = np.degrees(np.asarray(pol, float))
    if not nearest:
        return (pol_deg + 180.0) % 360.0 - 180.0
    tcm2_deg = np.degrees(np.asarray(tcm2, float))
    return (pol_deg - tcm2_deg + 90.0) % 180.0 - 90.0 + tcm2_deg


def plot_vs_em(path: Path, pol, tcm2, *, averaged: bool) -> None:
    """Polarized-light compass (blue) against the TCM2 (red), figs. 4.4 / 4.5.

    Fig. 4.4 (averaged) shows the candidate nearest the TCM2; fig. 4.5 (raw
    samples) the raw first candidate of eq. 4.6, so its 0/180 degree ambiguity shows.
    """
    plt, fig, ax = _figure(figsize=(7, 4))
    x = np.arange(len(pol))
    tcm2_deg = np.degrees(tcm2) if averaged else (np.degrees(tcm2) + 180.0) % 360.0 - 180.0
    pol_deg = displayed_heading_deg(pol, tcm2, nearest=averaged)
    style = ".-" if averaged else "."
    ax.plot(
        x, pol_deg, style, color="tab:blue", ms=4, label="polarized-light compass" + (" (mean of samples)" if averaged else "")
    )
    ax.plot(x, tcm2_deg, style, color="tab:red", ms=4, label="TCM2")
    ax.set_xlabel("position" if averaged else "sample")
    ax.set_ylabel("heading (deg CCW from east)")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path, dpi=120)


def plot_evector_field(path: Path, pans, tilts, angle, degree, model_angle, model_degree) -> None:
    """Polar plots of measured and model e-vectors (fig. 4.6, transformation of fig. 4.7).

    A point's polar angle is the pan (plus a half turn for negative tilt), its
    radius the absolute tilt in degrees; each bar is turned by the e-vector
    angle (sensor frame, relative to the pan direction) and scaled by the degree.
    """
    plt, fig, axes = _figure(1, 2, figsize=(11, 6.2))
    theta = np.asarray(pans) + np.where(np.asarray(tilts) < 0, np.pi, 0.0)
    radius = np.degrees(np.abs(tilts))
    x, y = radius * np.cos(theta), radius * np.sin(theta)
    scale = 12.0
    for ax, a, d, title in ((axes[0], angle, degree, "measured"), (axes[1], model_angle, model_degree, "sky model")):
        direction = np.asarray(pans) + np.asarray(a)
        dx, dy = scale * d * np.cos(direction) / 2, scale * d * np.sin(direction) / 2
        for xi, yi, u, v in zip(x, y, dx, dy):
            ax.plot([xi - u, xi + u], [yi - v, yi + v], "k-", lw=1.5)
        for r in np.unique(np.round(radius)):
            if r > 0:
                ax.add_patch(plt.Circle((0, 0), r, fill=False, color="0.8", lw=0.5))
        lim = radius.max() + scale
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_title(f"e-vectors, {title} (bar length ~ degree)", fontsize=10)
        ax.set_xlabel("tilt (deg) along pan 0")
    save_figure(fig, path, dpi=120)


def plot_partial_sky(path: Path, rows: list[dict]) -> None:
    """Heading error against clear-sky fraction, one curve per sun elevation (scan and zenith compass)."""
    plt, fig, ax = _figure(figsize=(7, 4.5))
    elevations = sorted({r["sun_elevation_deg"] for r in rows})
    for i, e in enumerate(elevations):
        sel = [r for r in rows if r["sun_elevation_deg"] == e]
        covers = sorted({r["cloud_cover"] for r in sel})
        clear, scan, zen = [], [], []
        for c in covers:
            rs = [r for r in sel if r["cloud_cover"] == c]
            clear.append(np.mean([r["clear_fraction"] for r in rs]))
            errs = np.array([r["scan_error_deg"] for r in rs])
            scan.append(np.sqrt(np.mean(np.where(np.isfinite(errs), errs, 180.0) ** 2)))
            zen.append(np.sqrt(np.nanmean(np.array([r["zenith_error_deg"] for r in rs]) ** 2)))
        color = f"C{i}"
        ax.plot(clear, scan, "o-", color=color, label=f"scan fit, sun {e:g} deg")
        ax.plot(clear, zen, "s--", color=color, alpha=0.6, label=f"zenith only (axial), sun {e:g} deg")
    ax.set_xlabel("clear-sky fraction")
    ax.set_ylabel("heading RMSE (deg)")
    ax.set_yscale("log")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    save_figure(fig, path, dpi=120)
