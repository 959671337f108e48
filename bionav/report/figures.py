"""Writing matplotlib figures the same way everywhere."""

from __future__ import annotations


def pyplot():
    """:mod:`matplotlib.pyplot` on the file-only Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path, *, dpi: int) -> None:
    """Lay out ``fig`` tightly, write it to ``path`` and close it.

    Closing matters in sweeps: an open pyplot figure keeps its memory until
    the process ends.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure made with :mod:`matplotlib.pyplot`.
    path : str or os.PathLike
        Output file; the format follows the suffix (``.png`` throughout bionav).
    dpi : int
        Resolution in dots per inch.
    """
    plt = pyplot()
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def grid_cell_axes(ax, *, fontsize: float | None = None) -> None:
    """Label ``ax`` as a map of grid positions: whole-cell ticks, axes "x (grid cells)" and "y (grid cells)".

    Grid positions are integers (cell indices, x to the right, y up, as the
    databases' grid frame), so a tick between two cells (0.5, 1.5) names no
    position; only integer ticks are drawn.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes showing a grid map (``imshow(..., origin="lower")`` or positions in grid units).
    fontsize : float, optional
        Font size of the axis labels (matplotlib's default when None).
    """
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("x (grid cells)", fontsize=fontsize)
    ax.set_ylabel("y (grid cells)", fontsize=fontsize)


#: the colour of values beyond a colour bar's upper end (distinct from every colour map bionav uses)
OVER_COLOUR = "tab:cyan"


def capped_colormap(name: str, *, over: str = OVER_COLOUR):
    """Colour map ``name`` whose values above ``vmax`` are drawn in ``over`` (not in the top colour).

    Use it with :func:`capped_colorbar`, e.g. for AAE maps capped at pi/2 (a random direction's expected
    error) while errors reach pi: a method worse than chance is then cyan, not the top colour.
    """
    import matplotlib

    return matplotlib.colormaps[name].with_extremes(over=over)


def capped_colorbar(fig, image, *, ax, label: str, **kwargs):
    """A colour bar for ``image`` (drawn with :func:`capped_colormap`) with an overflow triangle at the top.

    The triangle shows the over colour and the label says what it means, e.g. ``AAE$_s$ (rad), cyan >
    1.57``. Extra keyword arguments go to :meth:`matplotlib.figure.Figure.colorbar`.
    """
    vmax = image.get_clim()[1]
    text = f"{label}, cyan > {vmax:.3g}"
    return fig.colorbar(image, ax=ax, extend="max", label=text, **kwargs)


def draw_border_line(ax, point, tangent, style: str, label: str, *, color: str = "tab:blue", lw: float = 1.3) -> None:
    """A straight class border through ``point`` along ``tangent`` (data units), drawn across the axes' view.

    The line is moved along itself next to the view's centre and the axes' limits are kept, so
    a border whose reference point lies far outside the data still shows where the data are.
    """
    import numpy as np

    point, tangent = np.asarray(point, float), np.asarray(tangent, float)
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    span = 4 * max(x1 - x0, y1 - y0)
    p = point + np.outer(np.linspace(-span, span, 3), tangent)
    # move the border's reference point next to the data
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2])
    shift = ((centre - point) @ tangent) * tangent
    p = p + shift
    ax.plot(p[:, 0], p[:, 1], style, color=color, lw=lw, label=label)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
