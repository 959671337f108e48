"""The one CSV writer (bionav.files.write_csv_atomic) and the writers folded onto it: byte-identical files."""

from __future__ import annotations

import csv
from types import SimpleNamespace

import numpy as np


def _plain_csv(path, header, rows, *, dict_rows=False):
    """What the writers did before: ``open(path, "w", newline="")`` and ``csv.writer``/``csv.DictWriter``."""
    with open(path, "w", newline="", encoding="utf-8") as f:
        if dict_rows:
            w = csv.DictWriter(f, fieldnames=header)
            w.writeheader()
            w.writerows(rows)
        else:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(rows)


TRICKY = [["plain", 1, 2.5, None], ["a,b", 'say "hi"', "two\nlines", ""], ["ü µm", -0.0, float("nan"), True],
          [" lead", "trail ", "\r", 10**20]]


def test_write_csv_atomic_equals_the_csv_module_byte_for_byte(tmp_path):
    from bionav.files import write_csv_atomic

    header = ["name", "x", "y, z", 'quote"d']
    got = write_csv_atomic(tmp_path / "sub" / "new.csv", header, iter(TRICKY))
    _plain_csv(tmp_path / "old.csv", header, TRICKY)
    assert got == tmp_path / "sub" / "new.csv"
    assert got.read_bytes() == (tmp_path / "old.csv").read_bytes()
    # the dialect spelled out: CRLF lines, quotes only where needed, None empty
    assert got.read_bytes().startswith(b'name,x,"y, z","quote""d"\r\nplain,1,2.5,\r\n"a,b","say ""hi""","two\nlines",\r\n')
    assert [p.name for p in (tmp_path / "sub").iterdir()] == ["new.csv"]  # no temporary file left


def test_mapping_rows_equal_dict_writer(tmp_path):
    from bionav.files import write_csv_atomic

    header = ["a", "b", "c"]
    rows = [{"a": 1, "b": "x,y", "c": 0.25}, {"a": 2, "c": None}, {"b": 'q"'}]
    write_csv_atomic(tmp_path / "new.csv", header, ([r.get(c, "") for c in header] for r in rows))
    _plain_csv(tmp_path / "old.csv", header, rows, dict_rows=True)
    assert (tmp_path / "new.csv").read_bytes() == (tmp_path / "old.csv").read_bytes()


def test_an_empty_table_is_its_header(tmp_path):
    from bionav.files import write_csv_atomic

    assert write_csv_atomic(tmp_path / "t.csv", ["a", "b"], []).read_bytes() == b"a,b\r\n"


def test_per_snapshot_csv_is_unchanged(tmp_path):
    from bionav.experiments.grid_homing.run import write_per_snapshot_csv

    positions = np.array([[0, 0], [3, 1], [9, 16]])
    q = SimpleNamespace(aae_s=np.array([0.1, 1 / 3, np.pi]), mae_s=np.array([0.05, 0.2, 2.0]),
                        rr_s=np.array([1.0, 0.5, 0.0]))
    write_per_snapshot_csv(tmp_path / "new.csv", positions, q)
    _plain_csv(tmp_path / "old.csv", ["x", "y", "aae_s", "mae_s", "rr_s"],
               [[int(x), int(y), f"{a:.6f}", f"{m:.6f}", f"{r:.6f}"]
                for (x, y), a, m, r in zip(positions, q.aae_s, q.mae_s, q.rr_s)])
    assert (tmp_path / "new.csv").read_bytes() == (tmp_path / "old.csv").read_bytes()
    assert (tmp_path / "new.csv").read_text().splitlines()[2] == "3,1,0.333333,0.200000,0.500000"


def test_samples_csv_is_unchanged_and_reads_back(tmp_path):
    from bionav.light.bands import CHANNELS
    from bionav.spectral.csv_io import read_samples_csv, write_samples_csv
    from bionav.spectral.samples import SampleSet

    samples = SampleSet(np.array([[100.04, 2, 3, 4, 5], [6, 7, 8, 9, 1000.25], [1, 1, 1, 1, 1], [2, 2, 2, 2, 2.06]]),
                        np.array([True, False, True, False]), np.array(["overcast", "grass, wet", "", 'say "x"']),
                        np.array(["2009-06-17T12:00:00+02:00", "", "", ""]), "t")
    write_samples_csv(samples, tmp_path / "new.csv")
    _plain_csv(tmp_path / "old.csv", ["class", *CHANNELS, "kind", "time"],
               [["sky" if s else "object", *(f"{v:.1f}" for v in c), k, t]
                for c, s, k, t in zip(samples.counts, samples.is_sky, samples.kind, samples.time)])
    assert (tmp_path / "new.csv").read_bytes() == (tmp_path / "old.csv").read_bytes()
    back = read_samples_csv(tmp_path / "new.csv")
    np.testing.assert_allclose(back.counts, np.round(samples.counts, 1))
    assert back.kind.tolist() == ["overcast", "grass, wet", "", 'say "x"']
