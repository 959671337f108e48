"""Simulated sample sets and the CSV reader."""

import numpy as np
import pytest

from bionav.errors import UserError
from bionav.spectral.csv_io import read_samples_csv, write_samples_csv
from bionav.spectral.samples import sim_artificial, sim_natural
from bionav.stats import fisher_lda


@pytest.fixture(scope="module")
def natural():
    return sim_natural(seed=1, n_objects=60, n_sky=50)


def test_sim_sizes_kinds_and_shared_sky(natural):
    assert natural.n_objects == 60 and natural.n_sky == 50
    assert natural.counts.shape == (110, 5)
    assert np.all((natural.counts >= 0) & (natural.counts <= 4095))
    art = sim_artificial(seed=1, n_objects=20, n_sky=50)
    # the thesis reuses its sky readings: same seed -> same sky samples
    np.testing.assert_array_equal(art.counts[art.is_sky], natural.counts[natural.is_sky])
    assert set(natural.kind[~natural.is_sky]) <= {"grass", "shrub", "flowers", "tree", "conifer", "dead_leaves",
                                                  "dead_wood", "tar", "rock", "gravel", "sand", "soil"}
    assert all(k.startswith(("paint", "plastic", "lacquered", "metal")) for k in art.kind[~art.is_sky])
    assert all(t.startswith("2006-0") for t in natural.time)
    # deterministic in the seed
    again = sim_natural(seed=1, n_objects=60, n_sky=50)
    np.testing.assert_array_equal(again.counts, natural.counts)


def test_uv_separates_better_than_ir(natural):
    j_uv = fisher_lda(natural.counts[:, 0], natural.is_sky).criterion
    j_ir = fisher_lda(natural.counts[:, 4], natural.is_sky).criterion
    j_uvir = fisher_lda(natural.counts[:, [0, 4]], natural.is_sky).criterion
    assert j_uvir > j_uv > 3 * j_ir


def test_csv_round_trip(tmp_path, natural):
    p = write_samples_csv(natural, tmp_path / "s.csv")
    back = read_samples_csv(p)
    np.testing.assert_allclose(back.counts, natural.counts, atol=0.051)
    np.testing.assert_array_equal(back.is_sky, natural.is_sky)
    np.testing.assert_array_equal(back.kind, natural.kind)
    np.testing.assert_array_equal(back.time, natural.time)


def _write(tmp_path, text):
    p = tmp_path / "x.csv"
    p.write_text(text)
    return p


GOOD = "class,UV,B,G,R,IR\nsky,3000,3000,2900,2800,2700\nsky,3100,3050,2950,2800,2750\n" \
       "object,1500,1800,2000,1900,2600\nobject,1400,1700,1900,1800,2500\n"


def test_csv_minimal_columns_any_case_and_order(tmp_path):
    p = _write(tmp_path, "ir,Class,uv,b,g,r,comment\n2700,SKY,3000,3000,2900,2800,x\n2750,sky,3100,3050,2950,2800,\n"
                         "2600,object,1500,1800,2000,1900,y\n2500,Object,1400,1700,1900,1800,z\n")
    s = read_samples_csv(p)
    np.testing.assert_array_equal(s.counts[0], [3000, 3000, 2900, 2800, 2700])
    np.testing.assert_array_equal(s.is_sky, [True, True, False, False])
    assert list(s.kind) == [""] * 4


@pytest.mark.parametrize(
    "text, needles",
    [
        (GOOD + "object,1400,,1900,1800,2500\n", ["line 6", "B", "missing"]),
        (GOOD + "object,1400,1700,1900,1800\n", ["line 6", "IR", "missing"]),
        (GOOD + "sky,3000,abc,2900,2800,2700\n", ["line 6", "B", "'abc'", "not a number"]),
        (GOOD + "object,1400,1700,1900,nan,2500\n", ["line 6", "R", "finite"]),
        (GOOD + "tree,1400,1700,1900,1800,2500\n", ["line 6", "'tree'", "sky", "object"]),
        ("class,UV,B,G,IR\nsky,1,2,3,4\n", ["missing column", "r", "class,UV,B,G,R,IR"]),
        ("class,UV,B,G,R,IR\nsky,1,2,3,4,5\nobject,1,2,3,4,5\n", ["1 sky", "1 object", "at least two"]),
        ("", ["empty"]),
    ],
)
def test_csv_errors_name_the_row(tmp_path, text, needles):
    with pytest.raises(UserError) as err:
        read_samples_csv(_write(tmp_path, text))
    msg = str(err.value)
    for n in needles:
        assert n in msg, (n, msg)


def test_csv_missing_file(tmp_path):
    with pytest.raises(UserError, match="does not exist"):
        read_samples_csv(tmp_path / "nope.csv")
