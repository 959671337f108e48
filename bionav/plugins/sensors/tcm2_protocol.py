"""TCM2 electronic compass output words (PNI TCM2, the thesis' reference compass).

Two output formats, both ``$...*hh`` with ``hh`` the XOR of every byte
between ``$`` and ``*`` as two upper-case hex digits, lines ending CR LF:

* standard: ``$C<heading>P<pitch>R<roll>X<bx>Y<by>Z<bz>T<temp>[E<code>]*hh``
  (fields may be disabled and then absent), e.g. ``$C328.3P28.4R-12.4T22.3*hh``;
* NMEA 0183: ``$HCHDM,<heading>,M*hh`` (magnetic heading only).

Headings are compass bearings in degrees, clockwise from magnetic north.
"""

from __future__ import annotations

import re

_FIELD = re.compile(r"([CPRXYZTE])(-?\d+(?:\.\d*)?)")
_FIELD_NAMES = {
    "C": "heading_deg",
    "P": "pitch_deg",
    "R": "roll_deg",
    "X": "bx_uT",
    "Y": "by_uT",
    "Z": "bz_uT",
    "T": "temperature_c",
    "E": "error_code",
}


class TCM2FormatError(ValueError):
    """A line that is not a valid TCM2 output word; ``kind`` is 'checksum' or 'garbage'."""

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


def checksum(body: str) -> int:
    """XOR of the bytes of ``body`` (the text between ``$`` and ``*``)."""
    value = 0
    for b in body.encode("ascii"):
        value ^= b
    return value


def format_standard(*, heading_deg: float, pitch_deg: float = 0.0, roll_deg: float = 0.0, temperature_c: float = 20.0) -> str:
    """A standard output word with compass, pitch, roll and temperature, CR LF terminated."""
    body = f"C{heading_deg:.1f}P{pitch_deg:.1f}R{roll_deg:.1f}T{temperature_c:.1f}"
    return f"${body}*{checksum(body):02X}\r\n"


def format_nmea(*, heading_deg: float) -> str:
    """An NMEA ``$HCHDM`` sentence, CR LF terminated."""
    body = f"HCHDM,{heading_deg:.1f},M"
    return f"${body}*{checksum(body):02X}\r\n"


def parse_line(line: str) -> dict:
    """Parse one output word.

    Parameters
    ----------
    line : str
        The line, with or without the CR LF.

    Returns
    -------
    dict
        ``format`` ('standard' or 'nmea') and the fields present, e.g.
        ``heading_deg``, ``pitch_deg``, ``roll_deg``, ``temperature_c``.

    Raises
    ------
    TCM2FormatError
        On a malformed line (``kind='garbage'``) or a checksum mismatch
        (``kind='checksum'``).
    """
    text = line.strip()
    m = re.fullmatch(r"\$([^*$]*)\*([0-9A-Fa-f]{2})", text)
    if not m:
        raise TCM2FormatError("garbage", f"not a TCM2 output word: {text!r}")
    body, given = m.group(1), int(m.group(2), 16)
    expected = checksum(body)
    if given != expected:
        raise TCM2FormatError("checksum", f"checksum {given:02X} != computed {expected:02X} in {text!r}")
    if body.startswith("HCHDM,"):
        parts = body.split(",")
        try:
            return {"format": "nmea", "heading_deg": float(parts[1])}
        except (IndexError, ValueError):
            raise TCM2FormatError("garbage", f"unreadable NMEA heading in {text!r}") from None
    fields = _FIELD.findall(body)
    if not fields or "".join(k + v for k, v in fields) != body or fields[0][0] != "C":
        raise TCM2FormatError("garbage", f"unreadable TCM2 fields in {text!r}")
    out: dict = {"format": "standard"}
    for key, value in fields:
        out[_FIELD_NAMES[key]] = int(value) if key == "E" else float(value)
    return out
