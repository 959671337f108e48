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
