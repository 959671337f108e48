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
