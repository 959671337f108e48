"""``python -m bionav.db``: look at a database, or export it as a folder.

    python -m bionav.db show <db> [--out DIR] [overrides ...]
    python -m bionav.db export <db> DIR [--bits 8|16] [--force | --resume] [overrides ...]
    python -m bionav.db camera <db> [--out DIR] [--cells N] [overrides ...]

Overrides are Hydra overrides of the composed config, e.g. ``db.seed=1``,
``db.image_size=[288,50]``, ``data_dir=/data/panoramas``, ``db.path=DIR``.
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from bionav.errors import UserError
from bionav.files import user_path


def _parser(names: list[str]) -> argparse.ArgumentParser:
    listing = ", ".join(names) if names else "(none found)"
    parser = argparse.ArgumentParser(
        prog="python -m bionav.db",
        description="Inspect or export a bionav image database.",
        epilog=f"databases: {listing}. Real databases are read from data_dir/<name> "
               "(data_dir= or BIONAV_DATA); db=folder reads db.path=DIR.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="{show,export,camera}")
    show = sub.add_parser("show", help="write a contact sheet and a grid map PNG",
                          description="Write <db>_contact.png (thumbnails laid out like the grid) and "
                                      "<db>_grid.png (which cells exist).",
                          epilog=f"databases: {listing}")
    show.add_argument("db", help="database name")
    show.add_argument("--out", type=Path, default=None, help="output folder (default: outputs/db/<db>)")
    show.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. db.seed=1 data_dir=DIR")
    export = sub.add_parser("export", help="write the database as <x>_<y>.png files (Vardy naming)",
                            description="Write every image as <x>_<y>.png in the Bielefeld convention, "
                                        "readable with db=folder db.path=DIR.",
                            epilog=f"databases: {listing}")
    export.add_argument("db", help="database name")
    export.add_argument("dir", type=Path, help="output folder")
    export.add_argument("--bits", type=int, choices=(8, 16), default=None,
                        help="PNG bit depth (default: 8 if lossless, else 16)")
    export.add_argument("--force", action="store_true", help="overwrite images already in DIR")
    export.add_argument("--resume", action="store_true",
                        help="continue an interrupted export of the same database into DIR (images written are kept)")
    export.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. db.seed=1")
    camera = sub.add_parser("camera", help="write raw mirror frames and unfolded panoramas of a stand-in",
                            description="Write <db>_camera.png: raw catadioptric frames of a few capture cells "
                                        "and their unfolded panoramas (db.realism=camera) next to the ideal ones "
                                        "(docs/databases.md).",
                            epilog=f"databases: {listing}")
    camera.add_argument("db", help="synthetic stand-in name (sim_...)")
    camera.add_argument("--out", type=Path, default=None, help="output folder (default: outputs/db/<db>)")
    camera.add_argument("--cells", type=int, default=3, help="number of capture cells shown (default 3)")
    camera.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. db.camera.psf_sigma_px=1.5")
    return parser


def run(argv: list[str]) -> int:
    """Run the command line (raises UserError for problems the user can fix)."""
    from bionav.db.compose import available_databases, compose_database
    from bionav.db.loading import load_database

    parser = _parser(available_databases())
    args, extra = parser.parse_known_args(argv)
    unknown = [a for a in extra if a.startswith("-") or "=" not in a]
    if unknown:
        parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    args.overrides = list(args.overrides) + extra
    composed = compose_database(args.db, args.overrides)
    if args.command == "export" and args.resume:  # nothing to continue: said before the database loads
        from bionav.db.export import SIDECAR

        if not (user_path(args.dir) / SIDECAR).is_file():
            raise UserError(f"--resume: {args.dir} holds no export of bionav to continue (no {SIDECAR}); export "
                            "without --resume (into an empty folder, or with --force).")
    if args.command == "camera":
        return _camera(args, composed)
    db = load_database(composed.db, data_dir=composed.data_dir, cache_dir=composed.cache_dir)
    if args.command == "show":
        from bionav.db.sheets import write_show

        out = user_path(args.out) if args.out is not None else Path("outputs") / "db" / args.db
        try:
            with _one_writer(out):
                paths = write_show(db, out)
        except OSError as exc:
            raise UserError(f"cannot write to {out}: {exc}; choose a writable folder with --out DIR.") from None
        nx, ny = db.grid_shape
        print(f"{db.name}: {len(db)} images of {db.images.shape[2]} x {db.images.shape[1]} pixels "
              f"on a {nx} x {ny} grid ({db.spacing_m:g} m spacing)")
        for path in paths:
            print(f"wrote {path}")
    else:
        from bionav.db.export import export_database

        with _one_writer(user_path(args.dir)):
            overrides = export_database(db, user_path(args.dir), bits=args.bits, overwrite=args.force,
                                        resume=args.resume)
        print(f"wrote {len(db)} images of {db.name} to {args.dir}")
        print("read back with: python -m bionav " + " ".join(overrides))
    return 0


def _one_writer(folder: Path):
    """Hold ``folder``'s lock while writing (a second ``python -m bionav.db`` into it is refused)."""
    from bionav.runlock import RunLock

    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create the output folder {folder}: {exc.strerror or exc}; choose a writable "
                        "folder.") from None
    return RunLock(folder, what="output folder", fix="Wait for that command to finish, or choose another folder.")


def _camera(args, composed) -> int:
    from bionav.db.loading import as_database_config
    from bionav.db.sheets import write_camera_sheet
    from bionav.db.synthetic import _camera_configs, get_spec

    cfg = as_database_config(composed.db)
    if cfg.source != "synthetic":
        raise UserError(f"db={args.db} is not a synthetic stand-in; the camera sheet exists for the sim_* "
                        "stand-ins (python -m bionav.db camera sim_original).")
    if not 1 <= args.cells <= 12:
        raise UserError(f"--cells {args.cells}: choose 1 to 12 cells.")
    spec = get_spec(cfg.name)
    size = cfg.image_size or spec.native_size
    camera, pose_error = _camera_configs(spec, cfg.camera, cfg.pose_error, spec.geometry(*size))
    out = args.out if args.out is not None else Path("outputs") / "db" / args.db
    try:
        path = write_camera_sheet(cfg.name, out, camera=camera, pose_error=pose_error, seed=cfg.seed,
                                  image_size=size, n_cells=args.cells)
    except OSError as exc:
        raise UserError(f"cannot write to {out}: {exc}; choose a writable folder with --out DIR.") from None
    print(f"wrote {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point: user errors become one message on stderr and exit status 2."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s: %(message)s")
    try:
        return run(sys.argv[1:] if argv is None else list(argv))
    except UserError as exc:
        print(f"bionav.db: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C, SIGTERM, SIGHUP (bionav.cli_main.run_main)
        how = (" Continue the export with the same command plus --resume."
               if (argv or sys.argv[1:])[:1] == ["export"] else "")
        print(f"bionav.db: error: interrupted; the files written so far are kept.{how}", file=sys.stderr)
        return 130
