"""The benchmark CLI: its table and its argument errors (no timing targets here)."""

import numba
import pytest

from bionav.bench.__main__ import main


def test_bench_prints_one_row_per_variant(capsys):
    code = main(["--method", "minwarping", "--repeat", "1", "--steps", "24",
                 "--size", "72", "12", "--render-size", "144", "24"])
    assert code == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| minwarping")]
    assert len(lines) == 2  # without and with compass acceleration
    cells = [[c.strip() for c in line.strip("|").split("|")] for line in lines]
    assert [c[3] for c in cells] == ["no", "0.25"]
    assert all(c[1] == "72x12" and c[2] == "24x24" and c[7] == str(numba.get_num_threads()) for c in cells)
    assert all(float(c[4]) > 0 and float(c[5]) > 0 for c in cells)


def test_bench_rejects_a_thread_count_out_of_range(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--threads", "0"])
    assert exc.value.code == 2
    assert "--threads must lie in 1.." in capsys.readouterr().err
