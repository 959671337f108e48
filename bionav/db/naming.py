"""File naming schemes of panoramic image databases, and their detection.

Three schemes are understood (``db.naming``):

``vardy``
    ``<x>_<y>.<png|pgm|ppm|jpg|jpeg|bmp>``: the image of grid cell ``(x, y)``
    (Vardy's Bielefeld databases, and what ``python -m bionav.db export``
    writes). Indices are used as they are.

``moeller``
    ``cv_<x>_<y>_bw<cutoff>.pgm`` (Möller's databases, e.g. *moeller1*,
    *roeben1*; ``<cutoff>`` is the Butterworth cutoff the images were filtered
    with) plus one metadata file ``*.db`` holding one line
    ``w xmin xmax ymin ymax vertRes horizon``. The file indices are grid
    coordinates shifted by the declared minimum, in the same directions:

        gx = x - xmin,   gy = y - ymin

    and the grid is ``(xmax - xmin + 1) x (ymax - ymin + 1)`` cells. This is
    how Möller's reference min-warping program reads these databases
    (WarpingSIMD, ``warpingSIMDTest.C``: image ``cv_<x + xmin>_<y + ymin>`` is
    grid cell ``(x, y)``, true home direction ``atan2(y_ss - y, x_ss - x)``,
    image columns growing with clockwise azimuth, column 0 along grid +x), so
    the presets keep the Bielefeld column convention (``db.azimuth=clockwise``,
    ``db.x_axis_column=0``). ``vertRes`` is the vertical angle per pixel (taken as radians if it is
    below 0.1, else as degrees: no plausible panorama has more than 0.1 rad or
    less than 0.1 degrees per row), ``horizon`` the horizon row. ``w`` is kept
    in the metadata (it is expected to equal the image width; a mismatch is
    logged). If a folder holds several cutoffs, ``db.extra.bw_cutoff`` picks one.
    Without a ``.db`` file the indices are used as they are (``xmin = ymin = 0``).

``csv``
    A file ``positions.csv`` (or the only ``*.csv`` of the folder) with rows
    ``x,y[,filename]`` (optional header naming the columns ``x``, ``y``,
    ``filename``). Without a filename column, row ``i`` belongs to the ``i``-th
    image file of the folder in natural sort order (``img2`` before ``img10``).

``auto`` picks ``moeller`` if any file matches it, else ``vardy`` if any file
matches it, else ``csv`` if there is a CSV file.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path

from bionav.db.imageio import IMAGE_EXTENSIONS
from bionav.errors import UserError

SCHEMES = ("auto", "vardy", "moeller", "csv")

_EXT = "|".join(e.lstrip(".") for e in IMAGE_EXTENSIONS)
VARDY_PATTERN = re.compile(rf"^(\d+)_(\d+)\.({_EXT})$", re.IGNORECASE)
MOELLER_PATTERN = re.compile(rf"^cv_(\d+)_(\d+)_bw([0-9][0-9.eE+-]*?)\.({_EXT})$", re.IGNORECASE)

#: Files that live in image folders and are never images (not reported as ignored).
_QUIET_FILES = {"thumbs.db", "desktop.ini", "readme.txt", "readme.md", "bionav-export.yaml"}


@dataclass
class Entry:
    """One image file and the grid cell it belongs to (bionav's grid frame)."""

    path: Path
    x: int
    y: int


@dataclass
class Scan:
    """What a folder holds under one naming scheme."""

    scheme: str
    entries: list[Entry]
    ignored: list[str] = field(default_factory=list)
    grid_shape: tuple[int, int] | None = None
    horizon_row: float | None = None
    rad_per_row: float | None = None
    meta: dict = field(default_factory=dict)


def _natural_key(name: str):
    return [int(tok) if tok.isdigit() else tok.lower() for tok in re.split(r"(\d+)", name)]


def _named_like_image(path: Path) -> bool:
    return bool(VARDY_PATTERN.match(path.name) or MOELLER_PATTERN.match(path.name))


def _listing(folder: Path) -> list[Path]:
    """Regular files of a folder, plus anything named like a database image.

    A directory, broken symlink or symlink loop named ``1_1.png`` is kept, so
    the loader reports it instead of silently dropping its grid cell.
    """
    return sorted((p for p in folder.iterdir()
                   if not p.name.startswith(".") and (p.is_file() or _named_like_image(p))),
                  key=lambda p: _natural_key(p.name))


def not_a_file_reason(path: Path) -> str | None:
    """Why ``path`` is not a readable regular file (directory, symlink loop, ...), or None."""
    import errno
    import os
    import stat

    try:
        mode = os.stat(path).st_mode
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            return "is a symbolic-link loop"
        if path.is_symlink():
            return f"is a symbolic link to {os.readlink(path)!r}, which does not exist"
        return f"cannot be accessed ({exc.strerror or exc})"
    if stat.S_ISDIR(mode):
        return "is a directory, not an image file"
    if not stat.S_ISREG(mode):
        return "is not a regular file (a device, pipe or socket)"
    return None


def describe_schemes() -> str:
    """One sentence listing the file names bionav understands (for error messages)."""
    return ("expected image files named <x>_<y>.png|pgm|jpg|bmp (Vardy naming), "
            "cv_<x>_<y>_bw<cutoff>.pgm with a one-line .db file (Möller naming), "
            "or a positions.csv with rows x,y[,filename]")


def scan_folder(folder: Path, *, naming: str = "auto", grid_shape=None, bw_cutoff=None) -> Scan:
    """List the image files of a database folder and their grid cells.

    Parameters
    ----------
    folder : Path
        The database directory (must exist).
    naming : {"auto", "vardy", "moeller", "csv"}
        Naming scheme; ``auto`` detects it (see the module docstring).
    grid_shape : sequence of 2 int, optional
        Declared ``(nx, ny)`` (kept for callers; the schemes do not need it).
    bw_cutoff : float or str, optional
        Möller naming: which Butterworth cutoff to read if several are present.

    Returns
    -------
    Scan
        Entries (not yet validated against the grid), the names of files that
        do not belong to the scheme, and metadata the scheme provides.

    Raises
    ------
    UserError
        Unknown scheme, no matching files, an unreadable ``.db``/CSV file, or
        several Möller cutoffs without ``db.extra.bw_cutoff``.
    """
    key = str(naming).strip().lower()
    if key not in SCHEMES:
        raise UserError(f"db.naming={naming!r} is not a naming scheme; use one of {', '.join(SCHEMES)}.")
    files = _listing(folder)
    if key == "auto":
        if any(MOELLER_PATTERN.match(p.name) for p in files):
            key = "moeller"
        elif any(VARDY_PATTERN.match(p.name) for p in files):
            key = "vardy"
        elif any(p.suffix.lower() == ".csv" for p in files):
            key = "csv"
        else:
            shown = ", ".join(p.name for p in files[:5]) + (" ..." if len(files) > 5 else "")
            found = f"it holds {len(files)} file(s): {shown}" if files else "it is empty"
            raise UserError(
                f"no database images found in {folder} ({found}); {describe_schemes()}. "
                "Point db.path (or data_dir) at the folder that holds the images."
            )
    if key == "vardy":
        scan = _scan_vardy(files)
    elif key == "moeller":
        scan = _scan_moeller(folder, files, grid_shape=grid_shape, bw_cutoff=bw_cutoff)
    else:
        scan = _scan_csv(folder, files)
    if not scan.entries:
        raise UserError(
            f"no images named in the {key} scheme found in {folder} (db.naming={naming}); "
            f"{describe_schemes()}. Rename the files, or set db.naming to the scheme they follow."
        )
    return scan


def _quiet(path: Path) -> bool:
    return path.name.lower() in _QUIET_FILES


def _scan_vardy(files: list[Path]) -> Scan:
    entries, ignored = [], []
    for path in files:
        match = VARDY_PATTERN.match(path.name)
        if match:
            entries.append(Entry(path, int(match.group(1)), int(match.group(2))))
        elif not _quiet(path):
            ignored.append(path.name)
    return Scan("vardy", entries, ignored)


def read_moeller_db(path: Path) -> dict:
    """Parse a Möller ``.db`` metadata file (one line ``w xmin xmax ymin ymax vertRes horizon``).

    Returns
    -------
    dict
        ``w``, ``xmin``, ``xmax``, ``ymin``, ``ymax`` (int), ``vert_res``
        (as written), ``rad_per_row`` (radians, see the module docstring) and
        ``horizon`` (row).
    """
    from bionav.datafile import read_user_text

    text = read_user_text(path, what="the Möller metadata file", kind="metadata", encoding="latin-1",
                          fix="Fix the file, or remove it and set db.grid_shape, db.horizon_row and db.rad_per_row.")
    tokens = text.split()
    try:
        values = [float(t) for t in tokens]
    except ValueError:
        values = []
    if len(values) != 7 or any(not float(v).is_integer() for v in values[:5]):
        raise UserError(
            f"the Möller metadata file {path} should hold one line of seven numbers "
            f"'w xmin xmax ymin ymax vertRes horizon' but holds {text.strip()[:80]!r}. "
            "Fix the file, or remove it and set db.grid_shape, db.horizon_row and db.rad_per_row."
        )
    w, xmin, xmax, ymin, ymax = (int(v) for v in values[:5])
    vert_res, horizon = values[5], values[6]
    if xmax < xmin or ymax < ymin or vert_res <= 0:
        raise UserError(
            f"the Möller metadata file {path} declares an empty grid or a non-positive vertical "
            f"resolution ({text.strip()[:80]!r}); fix the file."
        )
    rad_per_row = vert_res if vert_res < 0.1 else vert_res * 3.141592653589793 / 180.0
    return {"w": w, "xmin": xmin, "xmax": xmax, "ymin": ymin, "ymax": ymax,
            "vert_res": vert_res, "rad_per_row": rad_per_row, "horizon": horizon}


def _scan_moeller(folder: Path, files: list[Path], *, grid_shape, bw_cutoff) -> Scan:
    matched, ignored = [], []
    db_files = [p for p in files if p.suffix.lower() == ".db" and p.is_file() and not _quiet(p)]
    for path in files:
        match = MOELLER_PATTERN.match(path.name)
        if match:
            matched.append((path, int(match.group(1)), int(match.group(2)), match.group(3)))
        elif path not in db_files and not _quiet(path):
            ignored.append(path.name)
    cutoffs = sorted({m[3] for m in matched}, key=float)
    if bw_cutoff is not None:
        chosen = [c for c in cutoffs if abs(float(c) - float(bw_cutoff)) < 1e-9]
        if not chosen:
            raise UserError(
                f"db.extra.bw_cutoff={bw_cutoff} but the Möller images in {folder} have cutoffs "
                f"{', '.join(cutoffs)}; pick one of those."
            )
        keep = set(chosen)
    elif len(cutoffs) > 1:
        raise UserError(
            f"{folder} holds Möller images with several Butterworth cutoffs ({', '.join(cutoffs)}); "
            f"choose one with db.extra.bw_cutoff=<cutoff>, e.g. db.extra.bw_cutoff={cutoffs[0]}."
        )
    else:
        keep = set(cutoffs)
    matched = [m for m in matched if m[3] in keep]

    meta: dict = {"bw_cutoff": float(next(iter(keep))) if keep else None}
    shape = horizon = rad_per_row = None
    if len(db_files) > 1:
        raise UserError(
            f"{folder} holds several .db metadata files ({', '.join(p.name for p in db_files)}); "
            "a Möller database has exactly one. Remove the ones that do not belong."
        )
    if db_files:
        info = read_moeller_db(db_files[0])
        meta["db_file"] = db_files[0].name
        meta.update(info)
        xmin, ymin = info["xmin"], info["ymin"]
        shape = (info["xmax"] - info["xmin"] + 1, info["ymax"] - info["ymin"] + 1)
        horizon, rad_per_row = info["horizon"], info["rad_per_row"]
    else:
        xmin = ymin = 0
        meta["db_file"] = None
    meta["index_map"] = f"gx = x - {xmin}, gy = y - {ymin}"
    entries = [Entry(path, x - xmin, y - ymin) for path, x, y, _ in matched]
    return Scan("moeller", entries, ignored, shape, horizon, rad_per_row, meta)


def _parse_int(text: str, where: str) -> int:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value.is_integer():
        raise UserError(f"{where}: {text!r} is not an integer grid index; fix the CSV row.")
    return int(value)


def _scan_csv(folder: Path, files: list[Path]) -> Scan:
    csvs = [p for p in files if p.suffix.lower() == ".csv"]
    named = [p for p in csvs if p.name.lower() == "positions.csv"]
    if named:
        table = named[0]
    elif len(csvs) == 1:
        table = csvs[0]
    elif not csvs:
        raise UserError(f"db.naming=csv but {folder} has no positions.csv; write one with rows x,y[,filename].")
    else:
        raise UserError(
            f"{folder} holds several CSV files ({', '.join(p.name for p in csvs)}); name the one with "
            "the grid positions positions.csv."
        )
    from bionav.datafile import checked_path

    checked_path(table, what="the positions file", fix="Write rows x,y[,filename] (a few bytes per cell).",
                 kind="table")
    try:
        with open(table, newline="", encoding="utf-8-sig") as fh:
            rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise UserError(f"cannot read the positions file {table}: {exc}; fix or replace it.") from None
    if not rows:
        raise UserError(f"the positions file {table} is empty; write rows x,y[,filename].")
    columns = {"x": 0, "y": 1, "filename": 2}
    first = [c.strip().lower() for c in rows[0]]
    try:
        float(first[0])
        header = False
    except ValueError:
        header = True
    if header:
        aliases = {"file": "filename", "image": "filename", "name": "filename", "path": "filename"}
        names = [aliases.get(c, c) for c in first]
        if "x" not in names or "y" not in names:
            raise UserError(
                f"the header of {table} ({', '.join(rows[0])}) has no 'x' and 'y' columns; "
                "name the columns x,y[,filename] or drop the header."
            )
        columns = {k: names.index(k) for k in ("x", "y", "filename") if k in names}
        rows = rows[1:]
    width = max(len(r) for r in rows) if rows else 0
    has_files = "filename" in columns and columns["filename"] < width
    images = [p for p in files if p.suffix.lower() in IMAGE_EXTENSIONS and p.is_file()]
    if not has_files and len(images) != len(rows):
        raise UserError(
            f"{table} has {len(rows)} position rows without file names, but {folder} holds "
            f"{len(images)} image files; add a filename column (x,y,filename) or make the counts match."
        )
    entries, used = [], set()
    for i, row in enumerate(rows):
        where = f"{table.name} row {i + 1 + int(header)}"
        if len(row) <= max(columns["x"], columns["y"]):
            raise UserError(f"{where} has {len(row)} column(s), needs x and y; fix the row.")
        x = _parse_int(row[columns["x"]].strip(), where)
        y = _parse_int(row[columns["y"]].strip(), where)
        if x < 0 or y < 0:
            raise UserError(f"{where}: grid indices must be >= 0, got ({x}, {y}); shift the indices.")
        if has_files:
            name = row[columns["filename"]].strip() if len(row) > columns["filename"] else ""
            if not name:
                raise UserError(f"{where} has no file name; fill in the filename column.")
            path = (folder / name)
        else:
            path = images[i]
        used.add(path.resolve())
        entries.append(Entry(path, x, y))
    ignored = [p.name for p in files if p != table and p.resolve() not in used and not _quiet(p)]
    return Scan("csv", entries, ignored, meta={"csv_file": table.name})
