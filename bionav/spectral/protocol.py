"""bionav's line protocol for the five-channel sensor board (ADuC812).

The hand-held sensor of thesis 6.1 (Kollmeier et al. 2007) is an ADuC812
microcontroller with six 12-bit ADCs: five read the log-ratio amplifiers of the
UV, B, G, R and IR photodiodes, the sixth reads the amplifiers' reference. The
thesis does not document a host protocol; bionav defines this one (firmware
for the board, or an adapter, must speak it):

Serial line
    9600 baud, 8 data bits, no parity, 1 stop bit (8N1), no flow control.
    ASCII. The host ends commands with ``\\r``; the device ends every reply
    line with ``\\r\\n``. The device does not echo.

``M<n>\\r`` — measure
    ``n`` is a decimal integer from 1 to 1000. The device takes ``n``
    subsequent readings (about 0.5 ms apart) and answers with ``n`` lines
    ``<uv>,<b>,<g>,<r>,<ir>,<ref>\\r\\n`` — six decimal integers in 0..4095
    (12-bit ADC counts of the log signals and of the reference), no spaces —
    followed by the line ``OK\\r\\n``.

``?\\r`` — identify
    The device answers one line, e.g.
    ``SPECTRAL5 ADuC812 fw1.0 ch=UV350,B440,G500,R680,IR800\\r\\n``.

Errors
    Any command the device cannot execute is answered with the single line
    ``ERR <text>\\r\\n`` (e.g. ``ERR bad command``, ``ERR n out of range``).

Example session (host ``>``, device ``<``)::

    > ?\\r
    < SPECTRAL5 ADuC812 fw1.0 ch=UV350,B440,G500,R680,IR800\\r\\n
    > M2\\r
    < 2895,2910,2874,2701,2633,3277\\r\\n
    < 2893,2912,2871,2704,2630,3276\\r\\n
    < OK\\r\\n

The host driver (``sensor=spectral5_serial``) waits at most ``timeout_s`` for
each reply line; a silent device, a reply line that is not six integers in
range, or ``OK`` before ``n`` readings arrived ends the command with a
:class:`bionav.errors.DeviceError` naming the port and the command.
"""

from __future__ import annotations

import re

import numpy as np

#: Default serial settings: baud rate, data bits, parity, stop bits.
BAUDRATE = 9600
BYTESIZE = 8
PARITY = "N"
STOPBITS = 1
#: Largest count of the 12-bit ADC.
FULL_SCALE = 4095
#: Largest ``n`` a single ``M<n>`` command may request.
MAX_READINGS = 1000
#: Identification line the fake device (and the reference firmware) sends.
IDENT = "SPECTRAL5 ADuC812 fw1.0 ch=UV350,B440,G500,R680,IR800"

_READING = re.compile(rb"^(\d{1,4}),(\d{1,4}),(\d{1,4}),(\d{1,4}),(\d{1,4}),(\d{1,4})$")


class ProtocolError(ValueError):
    """A reply line that does not follow the protocol."""


def measure_command(n: int) -> bytes:
    """The bytes of ``M<n>\\r``."""
    if not 1 <= int(n) <= MAX_READINGS:
        raise ValueError(f"n must be in 1..{MAX_READINGS}, got {n}")
    return f"M{int(n)}\r".encode("ascii")


IDENT_COMMAND = b"?\r"


def parse_reading(line: bytes) -> tuple[int, int, int, int, int, int]:
    """Parse one reading line (without or with its ``\\r\\n``).

    Returns
    -------
    tuple of int
        ``(uv, b, g, r, ir, ref)`` counts.

    Raises
    ------
    ProtocolError
        When the line is not six comma-separated integers in 0..4095.
    """
    m = _READING.match(line.rstrip(b"\r\n"))
    if not m:
        raise ProtocolError(f"not a reading line: {line!r}")
    values = tuple(int(v) for v in m.groups())
    if max(values) > FULL_SCALE:
        raise ProtocolError(f"count above {FULL_SCALE} in {line!r}")
    return values


def format_reading(values) -> bytes:
    """Encode ``(uv, b, g, r, ir, ref)`` as one reply line with ``\\r\\n``."""
    return (",".join(str(int(v)) for v in values) + "\r\n").encode("ascii")


#: MCAP topic of raw readings (the convention of ``sensor=replay``: one message per ``read()``).
RAW_TOPIC = "/sensor/raw"
#: Schema name and JSON schema of one raw reading message.
RAW_SCHEMA_NAME = "bionav.Spectral5Reading"
RAW_SCHEMA = {
    "type": "object",
    "title": RAW_SCHEMA_NAME,
    "description": "The reply to one measure command of the five-channel log sensor: n readings of "
                   "uv, b, g, r, ir, ref 12-bit ADC counts.",
    "properties": {
        "counts": {"type": "array", "items": {"type": "array", "items": {"type": "integer"},
                                               "minItems": 6, "maxItems": 6}},
    },
    "required": ["counts"],
}


def reading_message(readings) -> dict:
    """A raw reply ``(n, 6)`` as the dict ``read()`` returns and ``/sensor/raw`` records."""
    return {"counts": np.asarray(readings, dtype=np.int64).reshape(-1, 6).tolist()}


def reading_counts(message) -> np.ndarray:
    """Inverse of :func:`reading_message`: the ``(n, 6)`` int array of a raw reading dict."""
    return np.asarray(message["counts"], dtype=np.int64).reshape(-1, 6)
