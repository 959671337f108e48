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


def recover(src: str | Path, dst: str | Path) -> RecoveryReport:
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
    """
    src, dst = Path(src), Path(dst)
    if not src.is_file():
        raise UserError(f"the log file {src} does not exist; pass the path of the damaged run.mcap.")
    if src.resolve() == dst.resolve():
        raise UserError("recover writes a new file: give an output path different from the input.")
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    out_schema: dict[int, int] = {}
    out_channel: dict[int, int] = {}
    n_msg = n_att = n_meta = 0
    truncated = False
    error = None
    with open(src, "rb") as fin, open(dst, "wb") as fout:
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
        except Exception as exc:  # the truncated tail
            truncated = True
            error = f"{type(exc).__name__}: {exc}"
        writer.finish()
    return RecoveryReport(n_msg, len(out_channel), n_att, n_meta, truncated, error)
