"""MCAP logs: writing with periodic flushes, reading, recovery."""

from bionav.logs.reader import read_attachment, read_messages, read_metadata
from bionav.logs.recover import recover
from bionav.logs.writer import McapLog

__all__ = ["McapLog", "read_messages", "read_attachment", "read_metadata", "recover"]
