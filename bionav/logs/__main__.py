"""``python -m bionav.logs info FILE.mcap``, ``recover IN OUT``, ``export-ros2 RUN OUT`` and ``layout NAME``."""

from __future__ import annotations

import argparse
import sys
from collections import Counter

from bionav.errors import UserError


def _info(path: str) -> None:
    try:
        _print_info(path)
    except (UserError, BrokenPipeError):
        raise
    except Exception as exc:  # a damaged file: a cut-off summary, a flipped byte in a record
        raise UserError(
            f"{path} is damaged and cannot be summarised ({type(exc).__name__}: {str(exc)[:200]}); rebuild a readable "
            f"log from its intact records with `python -m bionav.logs recover {path} repaired.mcap`."
        ) from None


def _print_info(path: str) -> None:
    from mcap.reader import make_reader

    from bionav.logs.reader import _open

    with _open(path) as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            raise UserError(f"{path} has no summary section; repair it with `python -m bionav.logs recover`.")
        stats = summary.statistics
        counts = Counter()
        for channel_id, n in stats.channel_message_counts.items():
            counts[channel_id] = n
        duration = (stats.message_end_time - stats.message_start_time) / 1e9 if stats.message_count else 0.0
        print(f"file:        {path}")
        print(f"messages:    {stats.message_count}")
        print(f"duration:    {duration:.3f} s")
        print(f"attachments: {stats.attachment_count}   metadata: {stats.metadata_count}")
        print("channels:")
        for channel_id, channel in sorted(summary.channels.items()):
            schema = summary.schemas.get(channel.schema_id)
            name = schema.name if schema else "(no schema)"
            print(f"  {channel.topic:40s} {counts[channel_id]:8d}  {name}")
        f.seek(0)
        for meta in make_reader(f).iter_metadata():
            print(f"metadata {meta.name}:")
            for key, value in sorted(meta.metadata.items()):
                print(f"  {key} = {value}")


def _print_results(results: dict) -> None:
    """What the recovered log holds, as metrics of the run that was cut short."""
    for topic, n in sorted(results.get("messages", {}).items()):
        print(f"  {topic:40s} {n:8d} messages")
    if "n_home_vectors" in results:
        aae = results["aae_logged"]
        print(f"home vectors logged: {results['n_home_vectors']} of {results['n_snapshots']} snapshots "
              f"({results['n_complete_rows']} whole rows); AAE over them: "
              + ("none" if aae is None else f"{aae:.4f} rad"))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bionav.logs", description="Inspect and repair bionav MCAP logs.")
    sub = parser.add_subparsers(dest="command", required=True)
    p_info = sub.add_parser("info", help="summarise a log: topics, counts, schemas, metadata")
    p_info.add_argument("file")
    p_rec = sub.add_parser("recover", help="rewrite a truncated log into a valid, indexed one")
    p_rec.add_argument("input")
    p_rec.add_argument("output")
    p_rec.add_argument("--force", action="store_true", help="overwrite an existing output file")
    p_exp = sub.add_parser("export-ros2", help="write a run's views, poses, home vectors and other messages as a "
                                                "ROS 2 bag of standard message types (needs bionav[ros])")
    p_exp.add_argument("run", help="a run directory or its run.mcap")
    p_exp.add_argument("output", help="the ROS 2 bag folder to create")
    p_exp.add_argument("--storage", choices=("mcap", "sqlite3"), default="mcap", help="the bag's storage (default mcap)")
    p_exp.add_argument("--force", action="store_true", help="replace an existing output folder")
    p_lay = sub.add_parser("layout", help="print a Foxglove layout shipped with bionav (import it in Foxglove: "
                                          "Layouts, Import from file)")
    p_lay.add_argument("name", choices=("grid_homing", "compass"))
    args = parser.parse_args(argv)
    try:
        if args.command == "info":
            _info(args.file)
        elif args.command == "layout":
            from bionav.logs.foxglove import foxglove_layout

            print(foxglove_layout(args.name), end="")
        elif args.command == "export-ros2":
            from bionav.logs.ros2 import export_ros2

            counts = export_ros2(args.run, args.output, storage=args.storage, overwrite=args.force)
            print(f"wrote {sum(counts.values())} messages to the ROS 2 bag {args.output} ({args.storage}): "
                  + ", ".join(f"{n} {t}" for t, n in sorted(counts.items())))
        else:
            from bionav.logs.recover import recover

            report = recover(args.input, args.output, overwrite=args.force)
            state = "truncated input" if report.truncated else "intact input"
            print(
                f"recovered {report.messages} messages on {report.channels} channels, "
                f"{report.attachments} attachments, {report.metadata} metadata records ({state}) -> {args.output}"
            )
            _print_results(report.results or {})
    except UserError as exc:
        print(f"bionav.logs: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav.logs")
