"""``python -m bionav.report DIR``: rebuild the results table of a sweep or any tree of runs."""

from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bionav.report",
        description=(
            "Collect every run below DIR into summary.csv and summary.md "
            "(one row per run, failed ones included) and print the table."
        ),
    )
    parser.add_argument("dir", help="a sweep directory (multirun/...) or any directory holding runs")
    args = parser.parse_args(argv)
    from bionav.files import user_path

    root = user_path(args.dir)
    if not root.is_dir():
        print(f"bionav.report: error: {root} is not a directory; pass a sweep or run directory.", file=sys.stderr)
        return 2
    from bionav.report.sections import extra_sections
    from bionav.report.summary import write_summary
    from bionav.runlock import RunLock, settle_stale_runs

    # one writer of summary.csv / summary.md per directory; a stale lock is taken over
    with RunLock(root, what="directory", fix="Wait for the other `python -m bionav.report` to finish."):
        settle_stale_runs(root)  # runs whose process was killed say "interrupted", not "running"
        csv_path, md_path, rows = write_summary(root)
        if not rows:
            print(f"bionav.report: error: no runs (metrics.json) found below {root}.", file=sys.stderr)
            return 2
        text = md_path.read_text()
        sections = extra_sections(root, rows)
        if sections:
            text = text + "\n" + "\n\n".join(sections) + "\n"
            md_path.write_text(text)
    print(text)
    print(f"written: {csv_path}, {md_path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav.report")
