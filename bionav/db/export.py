"""Writing any database as a folder in Vardy naming (Bielefeld convention)."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from bionav.db.conventions import from_canonical
from bionav.db.database import ImageDatabase
from bionav.db.imageio import encode_image
from bionav.db.naming import VARDY_PATTERN
from bionav.errors import UserError
from bionav.files import cache_key, write_atomic

log = logging.getLogger(__name__)

SIDECAR = "bionav-export.yaml"


def exact_in_8bit(images: np.ndarray) -> bool:
    """True if every value is (within float32 rounding) a multiple of 1/255."""
    scaled = np.asarray(images, dtype=np.float64) * 255.0
    return bool(np.all(np.abs(scaled - np.rint(scaled)) < 1e-3))


def export_database(db: ImageDatabase, out_dir: Path, *, bits: int | None = None,
                    overwrite: bool = False, resume: bool = False) -> list[str]:
    """Write ``db`` as ``<x>_<y>.png`` files that ``db=folder`` reads back.

    The images are written in the Bielefeld convention (azimuth clockwise with
    the column index, column 0 along the grid's +x axis), i.e. the canonical
    columns mirrored: ``disk[:, c] = canonical[:, (-c) mod W]``. Geometry that
    the folder loader cannot infer from the files (grid shape, spacing, horizon
    row, vertical angle per row) goes into the overrides returned and into the
    sidecar ``bionav-export.yaml``.

    Parameters
    ----------
    db : ImageDatabase
    out_dir : Path
        Created if needed.
    bits : {8, 16}, optional
        PNG bit depth; by default 8 when that is lossless (every value a
        multiple of 1/255, e.g. synthetic databases with 8-bit quantisation)
        and 16 otherwise.
    overwrite : bool
        Allow writing into a folder that already holds ``<x>_<y>.*`` images.
    resume : bool
        Continue an interrupted export of the same database into ``out_dir``
        (its sidecar says which database and how): images already written are
        kept (each is written atomically, so none is half-written), the rest
        are written.

    Returns
    -------
    list of str
        The overrides that load the export back as the same database:
        ``db=folder db.path=... db.grid_shape=... db.spacing_m=...
        db.horizon_row=... db.rad_per_row=...``.
    """
    out_dir = Path(out_dir)
    if bits is None:
        bits = 8 if exact_in_8bit(db.images) else 16
    digest = cache_key({"bits": bits, "positions": np.asarray(db.positions).tolist()}, db.images)
    done = _resumable(out_dir, digest) if resume else None
    if done is None:
        _prepare_folder(out_dir, overwrite=overwrite)
    if np.any(np.asarray(db.headings) != 0):
        log.warning("database %s has rotated views; the export writes them as they are and "
                    "reads back with heading 0", db.name)
    overrides = _reload_overrides(db, out_dir)
    disk = from_canonical(db.images, azimuth="clockwise", x_axis_column=0.0)
    try:
        _write_sidecar(db, out_dir, overrides, bits=bits, digest=digest, complete=False)
        for (x, y), image in zip(db.positions, disk):
            name = f"{int(x)}_{int(y)}.png"
            if done is None or name not in done:
                write_atomic(out_dir / name, lambda f, image=image: f.write(encode_image(image, bits=bits)))
        _write_sidecar(db, out_dir, overrides, bits=bits, digest=digest, complete=True)
    except OSError as exc:
        raise UserError(f"cannot write the exported images to {out_dir}: {exc}; check the folder's "
                        "permissions and free space.") from None
    return overrides


def _resumable(out_dir: Path, digest: str) -> set[str] | None:
    """The images an interrupted export of this database left in ``out_dir`` (``--resume``)."""
    import yaml

    sidecar = out_dir / SIDECAR
    try:
        info = yaml.safe_load(sidecar.read_text(encoding="utf-8")) if sidecar.is_file() else None
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        info = None
    if not isinstance(info, dict) or "digest" not in info:
        raise UserError(f"--resume: {out_dir} holds no export of bionav to continue (no {SIDECAR} with its digest); "
                        "export without --resume (into an empty folder, or with --force).")
    if info.get("digest") != digest:
        raise UserError(f"--resume: {out_dir} holds the export of another database or another bit depth "
                        f"({info.get('name')}, {info.get('bits')} bit); give the same database, overrides and --bits "
                        "as the export you continue, or export into another folder.")
    return {p.name for p in out_dir.iterdir() if VARDY_PATTERN.match(p.name)}


def _prepare_folder(out_dir: Path, *, overwrite: bool) -> None:
    """Create ``out_dir``; refuse one that holds ``<x>_<y>.*`` images unless ``overwrite`` (then delete them)."""
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create the export folder {out_dir}: {exc.strerror or exc}; "
                        "choose a writable directory.") from None
    existing = [p.name for p in out_dir.iterdir() if VARDY_PATTERN.match(p.name)]
    if existing and not overwrite:
        raise UserError(
            f"{out_dir} already holds database images ({', '.join(existing[:3])}"
            f"{' ...' if len(existing) > 3 else ''}); continue an interrupted export of the same database with "
            f"--resume, export into an empty folder, or pass --force to overwrite."
        )
    for name in existing:
        (out_dir / name).unlink()


def _reload_overrides(db: ImageDatabase, out_dir: Path) -> list[str]:
    """The command-line overrides that load the export in ``out_dir`` back as ``db``."""
    g = db.geometry
    return [
        "db=folder",
        f"db.path={out_dir.resolve()}",
        "db.naming=vardy",
        f"db.grid_shape=[{db.grid_shape[0]},{db.grid_shape[1]}]",
        f"db.spacing_m={float(db.spacing_m)!r}",
        f"db.horizon_row={float(g.horizon_row)!r}",
        f"db.rad_per_row={float(g.rad_per_row)!r}",
    ]


def _write_sidecar(db: ImageDatabase, out_dir: Path, overrides: list[str], *, bits: int, digest: str,
                   complete: bool) -> None:
    """``bionav-export.yaml``: what the folder loader cannot infer from the files, how to load them, and
    whether the export is complete (``complete: false`` while it runs; ``--resume`` continues it)."""
    g = db.geometry
    sidecar = [
        f"# {len(db)} images of database {db.name!r} exported by python -m bionav.db export",
        "# Vardy naming <x>_<y>.png, Bielefeld convention (azimuth clockwise, column 0 along +x).",
        "# Load with: python -m bionav " + " ".join(overrides),
        f"name: {db.name}",
        f"bits: {bits}",
        f"grid_shape: [{db.grid_shape[0]}, {db.grid_shape[1]}]",
        f"spacing_m: {float(db.spacing_m)!r}",
        f"width: {g.width}",
        f"height: {g.height}",
        f"horizon_row: {float(g.horizon_row)!r}",
        f"rad_per_row: {float(g.rad_per_row)!r}",
        f"digest: {digest}",
        f"complete: {'true' if complete else 'false'}",
    ]
    write_atomic(out_dir / SIDECAR, "\n".join(sidecar) + "\n")
