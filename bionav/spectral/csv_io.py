"""Read and write five-channel sample sets as CSV.

Format (one header line, then one data point per line; comma separated;
column names case-insensitive and in any order):

``class``
    ``sky`` (background) or ``object`` (foreground).
``UV,B,G,R,IR``
    Channel readings in ADC counts (numbers; means of several readings may be
    fractional).
``kind`` (optional)
    Sky type or material, free text.
``time`` (optional)
    ISO 8601 time of the reading, free text.

Other columns are ignored. Lines starting with ``#`` and blank lines are skipped.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from bionav.errors import UserError
from bionav.files import write_csv_atomic
from bionav.light.bands import CHANNELS
from bionav.spectral.samples import SampleSet

_CLASS_VALUES = {"sky": True, "object": False}


def read_samples_csv(path) -> SampleSet:
    """Read a labelled sample set from CSV (see the module docstring for the format).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    SampleSet

    Raises
    ------
    UserError
        For a missing or unreadable file, missing columns, a missing or
        non-numeric cell, an unknown class (naming the line and column), or
        fewer than two samples of either class.
    """
    path = Path(path)
    fix = "Fix the file, or use data=sim_natural / data=sim_artificial for a simulated set."
    if not path.exists():
        raise UserError(f"Sample CSV {str(path)!r} does not exist. Point data.path at a CSV file with columns "
                        f"class,UV,B,G,R,IR[,kind,time]. {fix}")
    from bionav.datafile import read_user_text

    text = read_user_text(path, what="The sample CSV", fix=fix, kind="table")
    lines = [(i + 1, line) for i, line in enumerate(text.splitlines()) if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise UserError(f"Sample CSV {str(path)!r} is empty; it needs a header line class,UV,B,G,R,IR and data lines. {fix}")
    header_line, header = lines[0]
    names = [h.strip() for h in next(csv.reader([header]))]
    lower = [n.lower() for n in names]
    required = ["class"] + [c.lower() for c in CHANNELS]
    missing = [r for r in required if r not in lower]
    if missing:
        raise UserError(f"Sample CSV {str(path)!r}, header on line {header_line}: missing column(s) "
                        f"{', '.join(missing)} (found: {', '.join(names) or 'none'}). The header must name "
                        f"class,UV,B,G,R,IR (optional kind,time). {fix}")
    col = {name: lower.index(name) for name in required + [o for o in ("kind", "time") if o in lower]}
    counts, labels, kinds, times = [], [], [], []
    for lineno, line in lines[1:]:
        row = next(csv.reader([line]))

        def cell(name, row=row, lineno=lineno):
            i = col[name]
            value = row[i].strip() if i < len(row) else ""
            if value == "" and name in required:
                raise UserError(f"Sample CSV {str(path)!r}, line {lineno}: the {names[i]} cell is missing. "
                                f"Every data line needs class,UV,B,G,R,IR values. {fix}")
            return value

        cls = cell("class").lower()
        if cls not in _CLASS_VALUES:
            raise UserError(f"Sample CSV {str(path)!r}, line {lineno}: class {cell('class')!r} is neither 'sky' nor "
                            f"'object'. {fix}")
        values = []
        for ch in CHANNELS:
            raw = cell(ch.lower())
            try:
                v = float(raw)
            except ValueError:
                raise UserError(f"Sample CSV {str(path)!r}, line {lineno}: the {ch} cell {raw!r} is not a number "
                                f"(counts expected). {fix}") from None
            if not np.isfinite(v):
                raise UserError(f"Sample CSV {str(path)!r}, line {lineno}: the {ch} cell {raw!r} is not a finite "
                                f"number. {fix}")
            values.append(v)
        counts.append(values)
        labels.append(_CLASS_VALUES[cls])
        kinds.append(cell("kind") if "kind" in col else "")
        times.append(cell("time") if "time" in col else "")
    labels = np.array(labels, dtype=bool)
    if np.count_nonzero(labels) < 2 or np.count_nonzero(~labels) < 2:
        raise UserError(f"Sample CSV {str(path)!r} holds {np.count_nonzero(labels)} sky and "
                        f"{np.count_nonzero(~labels)} object samples; the discriminant analysis needs at least "
                        f"two of each. {fix}")
    return SampleSet(np.array(counts, dtype=float), labels, np.array(kinds, dtype=str),
                     np.array(times, dtype=str), str(path))


def write_samples_csv(samples: SampleSet, path) -> Path:
    """Write a sample set in the format :func:`read_samples_csv` reads; returns the path."""
    path = Path(path)
    write_csv_atomic(path, ["class", *CHANNELS, "kind", "time"],
                     (["sky" if sky else "object", *(f"{v:.1f}" for v in c), k, t]
                      for c, sky, k, t in zip(samples.counts, samples.is_sky, samples.kind, samples.time)))
    return path
