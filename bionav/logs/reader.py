"""Reading ``run.mcap`` files back (replay, inspection)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Iterable, Iterator

from mcap.reader import make_reader

from bionav.errors import UserError


def _open(path: str | Path):
    from bionav.files import user_path
    from bionav.logs.recover import check_mcap

    path = user_path(path)
    check_mcap(path)
    return open(path, "rb")


def read_messages(path: str | Path, topics: Iterable[str] | None = None) -> Iterator[tuple[str, int, dict]]:
    """Yield ``(topic, log_time_ns, message)`` for every JSON message, in log-time order.

    Parameters
    ----------
    path : path-like
        An MCAP file written by :class:`bionav.logs.writer.McapLog`.
    topics : iterable of str, optional
        Only these topics.

    Raises
    ------
    UserError
        When the file is missing or unreadable (a truncated file needs
        ``python -m bionav.logs recover`` first).
    """
    with _open(path) as f:
        reader = make_reader(f)
        try:
            for schema, channel, message in reader.iter_messages(
                topics=None if topics is None else list(topics), log_time_order=True
            ):
                yield channel.topic, message.log_time, json.loads(message.data)
        except UserError:
            raise
        except Exception as exc:
            raise UserError(
                f"cannot read {path}: {exc}. If the run crashed while writing, repair the log with "
                f"`python -m bionav.logs recover {path} repaired.mcap`."
            ) from None


def read_attachment(path: str | Path, name: str) -> bytes | None:
    """The data of the first attachment called ``name``, or ``None``."""
    with _open(path) as f:
        reader = make_reader(f)
        for attachment in reader.iter_attachments():
            if attachment.name == name:
                return attachment.data
    return None


def read_metadata(path: str | Path) -> dict[str, dict[str, str]]:
    """All metadata records, keyed by record name."""
    with _open(path) as f:
        reader = make_reader(f)
        return {m.name: dict(m.metadata) for m in reader.iter_metadata()}


def read_recorded_messages(path: str | Path, topics: Iterable[str]) -> list[tuple[str, dict]]:
    """``(topic, message)`` of every complete JSON message of ``topics``, in file order, also from a log that a
    crash cut off (SIGKILL, a full disk): the messages before the damage; none from a file that is not a log.

    For continuing a run from what an earlier attempt logged (``bionav.resume=true``).
    """
    from mcap.exceptions import McapError
    from mcap.reader import NonSeekingReader

    wanted = set(topics)
    out: list[tuple[str, dict]] = []
    try:
        with _open(path) as f:
            for _schema, channel, message in NonSeekingReader(f, validate_crcs=True).iter_messages():
                if channel.topic in wanted and channel.message_encoding == "json":
                    out.append((channel.topic, json.loads(message.data)))
    except (UserError, McapError, ValueError, OSError, EOFError):
        pass  # the damage: what came before it is kept
    return out
