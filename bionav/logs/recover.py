"""Repair of truncated MCAP logs (a crash in the middle of writing)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mcap.records import Attachment, Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType, Writer

from bionav.errors import UserError


@dataclass(frozen=True)
class RecoveryReport:
    """What :func:`recover` kept."""

    messages: int
    channels: int
    attachments: int
    metadata: int
    truncated: bool
    error: str | None
    #: what the recovered messages hold (:func:`logged_results`)
    results: dict | None = None


MAGIC = b"\x89MCAP0\r\n"


def check_mcap(path: str | Path) -> None:
    """Raise :class:`UserError` unless ``path`` is a file starting with the MCAP magic bytes."""
    from bionav.datafile import checked_path

    path = Path(path)
    if path.is_dir():
        raise UserError(f"{path} is a directory, not a log file; pass the run.mcap inside it, "
                        f"e.g. {path / 'run.mcap'}.")
    # never open a FIFO or a device (reading it would block), nor a file larger than any log of a run
    checked_path(path, what="the log file", fix="Pass the path of a run.mcap written by a bionav run.", kind="log")
    try:
        with open(path, "rb") as f:
            head = f.read(len(MAGIC))
    except OSError as exc:
        raise UserError(f"cannot read {path}: {exc.strerror or exc}.") from None
    if head != MAGIC:
        what = "it is empty" if not head else "it does not start with the MCAP magic bytes"
        raise UserError(f"{path} is not an MCAP file ({what}); pass a run.mcap written by a bionav run.")


def recover(src: str | Path, dst: str | Path, *, overwrite: bool = False) -> RecoveryReport:
    """Copy every complete record of a (possibly truncated) MCAP file into a valid, indexed one.

    Records are read sequentially until the file ends or a record is cut
    off; complete chunks are unpacked, schemas and channels re-registered,
    and everything written into a new, properly finished file with summary
    and index.

    Parameters
    ----------
    src : path-like
        Damaged (or intact) input file.
    dst : path-like
        Output file; must differ from ``src``.
    overwrite : bool
        Replace an existing ``dst`` (refused otherwise: it may be a good log).

    Raises
    ------
    UserError
        When ``src`` is missing, a directory or not an MCAP file, or ``dst``
        cannot be written.
    """
    from bionav.files import not_a_regular_file, user_path

    src, dst = user_path(src), user_path(dst)
    check_mcap(src)
    if src.resolve() == dst.resolve():
        raise UserError("recover writes a new file: give an output path different from the input.")
    if dst.is_dir():
        raise UserError(f"the output {dst} is a directory; give a file name, e.g. {dst / 'fixed.mcap'}.")
    problem = not_a_regular_file(dst)
    if problem not in (None, "does not exist") and not dst.is_dir():
        raise UserError(f"the output {dst} {problem}; give the name of a new file, e.g. fixed.mcap.")
    if dst.exists() and not overwrite:
        raise UserError(f"the output {dst} exists; recover does not overwrite files (it could be a good log): "
                        f"choose another name, or pass --force.")
    try:
        fout = open(dst, "wb")
    except OSError as exc:
        raise UserError(f"cannot write the output {dst}: {exc.strerror or exc}; choose a writable place.") from None
    try:
        return _copy_records(src, dst, fout)
    except OSError as exc:  # disk full, quota, I/O error while writing the output
        fout.close()
        dst.unlink(missing_ok=True)
        raise UserError(f"cannot write the output {dst}: {exc.strerror or exc}; the input {src} is unchanged. "
                        f"Free space or choose another place for the output.") from None


def _copy_records(src: Path, dst: Path, fout) -> RecoveryReport:
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    out_schema: dict[int, int] = {}
    out_channel: dict[int, int] = {}
    n_msg = n_att = n_meta = 0
    truncated = False
    error = None
    with open(src, "rb") as fin, fout:
        writer = Writer(fout, compression=CompressionType.ZSTD)
        writer.start(profile="bionav", library="bionav recover")

        def handle(record) -> None:
            nonlocal n_msg, n_att, n_meta
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Chunk):
                for inner in breakup_chunk(record, validate_crc=True):
                    handle(inner)
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    return
                if channel.schema_id and channel.schema_id not in out_schema:
                    s = schemas[channel.schema_id]
                    out_schema[channel.schema_id] = writer.register_schema(s.name, s.encoding, s.data)
                if channel.id not in out_channel:
                    out_channel[channel.id] = writer.register_channel(
                        channel.topic, channel.message_encoding, out_schema.get(channel.schema_id, 0), channel.metadata
                    )
                writer.add_message(
                    out_channel[channel.id], record.log_time, record.data, record.publish_time, record.sequence
                )
                n_msg += 1
            elif isinstance(record, Attachment):
                writer.add_attachment(record.create_time, record.log_time, record.name, record.media_type, record.data)
                n_att += 1
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, record.metadata)
                n_meta += 1

        try:
            for record in StreamReader(fin, skip_magic=False).records:
                handle(record)
        except OSError:
            raise
        except Exception as exc:  # the truncated tail
            truncated = True
            error = f"{type(exc).__name__}: {exc}"
        writer.finish()
    return RecoveryReport(n_msg, len(out_channel), n_att, n_meta, truncated, error, logged_results(dst))


#: topics whose messages each hold home vectors of one snapshot: whole rows, and pairs of rows in progress
HOME_VECTOR_TOPICS = ("/grid_homing/snapshot_rows", "/grid_homing/partial_rows")


def logged_results(path: str | Path) -> dict:
    """Metrics rebuilt from the messages of a (recovered) log, for a run that never wrote its own.

    Home vectors (grid homing) are collected from
    :data:`HOME_VECTOR_TOPICS`, each (snapshot, current view) pair once
    (a whole row supersedes the partial messages of that row).

    Returns
    -------
    dict
        ``messages`` per topic; with home vectors also ``n_home_vectors``,
        ``n_snapshots``, ``n_complete_rows`` and ``aae_logged`` (mean angular
        error of the logged pairs, radians; pairs without a direction count
        as the experiment counts them).
    """
    import json
    import math
    from collections import Counter

    from mcap.reader import make_reader

    topics: Counter = Counter()
    rows: dict[tuple, list[float]] = {}  # snapshot -> the angular errors of its whole row
    partial: dict[tuple, dict[tuple, float]] = {}  # snapshot -> current cell -> angular error
    with open(path, "rb") as f:
        for _schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
            topics[channel.topic] += 1
            if channel.topic not in HOME_VECTOR_TOPICS:
                continue
            data = json.loads(message.data)
            snap = tuple(data.get("snapshot") or ())
            ae = list(data.get("ae") or [])
            if data.get("currents") is None:
                rows[snap] = [v for v in ae if v is not None and math.isfinite(v)]
            else:
                cells = partial.setdefault(snap, {})
                for cell, v in zip(data["currents"], ae):
                    if v is not None and math.isfinite(v):
                        cells[tuple(cell)] = v
    out: dict = {"messages": dict(topics)}
    if rows or partial:
        values = [v for snap in set(rows) | set(partial)
                  for v in (rows[snap] if snap in rows else partial[snap].values())]
        out.update(n_home_vectors=len(values), n_snapshots=len(set(rows) | set(partial)), n_complete_rows=len(rows),
                   aae_logged=sum(values) / len(values) if values else None)
    return out
