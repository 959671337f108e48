"""The shared figure helpers: Agg backend, file written, figure closed."""

import matplotlib

from bionav.report.figures import pyplot, save_figure


def test_save_figure_writes_a_png_and_closes_the_figure(tmp_path):
    plt = pyplot()
    assert matplotlib.get_backend().lower() == "agg"
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    path = tmp_path / "line.png"
    save_figure(fig, path, dpi=50)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert fig.number not in plt.get_fignums()
