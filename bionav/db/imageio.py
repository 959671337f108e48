"""Reading and writing single database images with OpenCV.

Every image is returned as a float32 grey image in ``[0, 1]``: 8-bit images
are divided by 255, 16-bit images by 65535 (PGM/PPM files by their declared
``maxval``, which OpenCV does not apply), colour images are converted to grey
with OpenCV's ITU-R BT.601 weights. Before decoding, the file is checked for
completeness (PNG ``IEND`` chunk, JPEG end-of-image marker, PNM pixel count,
BMP declared file size), because OpenCV silently returns a partially grey
image for a truncated JPEG.
"""

from __future__ import annotations

import re
import zlib
from pathlib import Path

import cv2
import numpy as np

IMAGE_EXTENSIONS = (".png", ".pgm", ".ppm", ".pnm", ".jpg", ".jpeg", ".bmp")


class ImageReadError(Exception):
    """A file that should hold an image cannot be decoded (message says why)."""


_PNM_HEADER = re.compile(rb"\AP([1-6])(?:\s|#[^\n]*\n)+(\d+)(?:\s|#[^\n]*\n)+(\d+)(?:(?:\s|#[^\n]*\n)+(\d+))?\s")


def _pnm_maxval(data: bytes) -> int | None:
    match = _PNM_HEADER.match(data)
    if match is None or match.group(4) is None:
        return None
    return int(match.group(4))


_PNG_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}


def _check_png(data: bytes) -> None:
    """Verify a PNG's chunk CRCs and its compressed pixel data before libpng sees it.

    libpng prints ``libpng error: ...`` on stderr for corrupt data (before
    OpenCV returns nothing); checking here gives one clean message instead.
    """
    pos, idat, header = 8, [], None
    while pos + 12 <= len(data):
        length = int.from_bytes(data[pos:pos + 4], "big")
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        crc = data[pos + 8 + length:pos + 12 + length]
        if len(body) != length or len(crc) != 4:
            raise ImageReadError(f"the PNG file is truncated inside its {kind.decode('latin-1')!r} chunk")
        if zlib.crc32(kind + body) != int.from_bytes(crc, "big"):
            raise ImageReadError(f"the PNG file is corrupt (checksum error in its {kind.decode('latin-1')!r} chunk)")
        if kind == b"IHDR":
            header = body
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if header is None or len(header) != 13 or not idat:
        raise ImageReadError("the PNG file is corrupt (no IHDR header or no IDAT pixel data)")
    try:
        pixels = zlib.decompress(b"".join(idat))
    except zlib.error as exc:
        raise ImageReadError(f"the PNG file is corrupt (its pixel data does not decompress: {exc})") from None
    width, height = int.from_bytes(header[0:4], "big"), int.from_bytes(header[4:8], "big")
    depth, colour, interlace = header[8], header[9], header[12]
    if interlace == 0 and colour in _PNG_CHANNELS:
        need = height * (1 + (width * depth * _PNG_CHANNELS[colour] + 7) // 8)
        if len(pixels) < need:
            raise ImageReadError(f"the PNG file is corrupt ({len(pixels)} of {need} pixel bytes)")


def _check_complete(data: bytes) -> None:
    """Raise ImageReadError if ``data`` is an image file that is cut short."""
    if len(data) == 0:
        raise ImageReadError("the file is empty")
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        if data.rstrip(b"\x00")[-12:] != b"\x00\x00\x00\x00IEND\xaeB`\x82":
            raise ImageReadError("the PNG file is truncated (no IEND chunk at its end)")
        _check_png(data)
    elif data.startswith(b"\xff\xd8"):
        if not data.rstrip(b"\x00\r\n ")[-2:] == b"\xff\xd9":
            raise ImageReadError("the JPEG file is truncated (no end-of-image marker)")
    elif data[:1] == b"P" and data[1:2] in (b"5", b"6"):
        match = _PNM_HEADER.match(data)
        if match is None or match.group(4) is None:
            raise ImageReadError("the PNM header is malformed")
        width, height, maxval = int(match.group(2)), int(match.group(3)), int(match.group(4))
        channels = 1 if match.group(1) == b"5" else 3
        need = width * height * channels * (1 if maxval < 256 else 2)
        if len(data) - match.end() < need:
            raise ImageReadError(
                f"the PNM file is truncated ({len(data) - match.end()} of {need} pixel bytes)"
            )
    elif data.startswith(b"BM") and len(data) >= 6:
        declared = int.from_bytes(data[2:6], "little")
        if declared > len(data):
            raise ImageReadError(f"the BMP file is truncated ({len(data)} of {declared} bytes)")


def to_grey_float(image: np.ndarray, *, maxval: float | None = None) -> np.ndarray:
    """Convert a decoded OpenCV image to a float32 grey image in ``[0, 1]``.

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, C), uint8, uint16 or float
        Image as returned by ``cv2.imread(..., cv2.IMREAD_UNCHANGED)`` (BGR or
        BGRA channel order).
    maxval : float, optional
        Value that maps to 1. Defaults to the dtype's maximum (255, 65535) or
        1 for float images.

    Returns
    -------
    ndarray, shape (H, W), float32
    """
    if maxval is None:
        maxval = float(np.iinfo(image.dtype).max) if np.issubdtype(image.dtype, np.integer) else 1.0
    grey = image
    if image.ndim == 3:
        if image.shape[2] == 1:
            grey = image[:, :, 0]
        elif image.shape[2] == 2:  # grey + alpha
            grey = image[:, :, 0]
        else:
            code = cv2.COLOR_BGRA2GRAY if image.shape[2] == 4 else cv2.COLOR_BGR2GRAY
            grey = cv2.cvtColor(image[:, :, :4] if image.shape[2] > 4 else image, code)
    out = grey.astype(np.float32) / np.float32(maxval)
    return np.clip(out, 0.0, 1.0, out=out)


def read_image(path: Path) -> np.ndarray:
    """Read one image file as a float32 grey image in ``[0, 1]``.

    Parameters
    ----------
    path : Path
        PNG, PGM/PPM, JPEG or BMP file, 8 or 16 bit, grey or colour.

    Returns
    -------
    ndarray, shape (H, W), float32

    Raises
    ------
    ImageReadError
        The file is empty, truncated or not decodable (the message says which).
    """
    from bionav.datafile import MAX_BYTES

    try:
        size = Path(path).stat().st_size
        if size > MAX_BYTES["image"]:  # refused before it is read (a 1 GiB image would not fit anyway)
            raise ImageReadError(f"it is {size / 2**20:.0f} MiB, more than the {MAX_BYTES['image'] // 2**20} MiB "
                                 "an image may have")
        data = Path(path).read_bytes()
    except OSError as exc:
        raise ImageReadError(f"the file cannot be read ({exc.strerror or exc})") from None
    _check_complete(data)
    image = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), cv2.IMREAD_UNCHANGED)
    if image is None or image.size == 0:
        raise ImageReadError("OpenCV cannot decode it as an image")
    maxval = None
    if data[:1] == b"P":
        maxval = _pnm_maxval(data)
    return to_grey_float(image, maxval=maxval)


def _levels(image: np.ndarray, bits: int) -> np.ndarray:
    if bits not in (8, 16):
        raise ValueError(f"bits must be 8 or 16, not {bits}")
    top = 255 if bits == 8 else 65535
    dtype = np.uint8 if bits == 8 else np.uint16
    return np.rint(np.clip(np.asarray(image, dtype=np.float64), 0.0, 1.0) * top).astype(dtype)


def write_image(path: Path, image: np.ndarray, *, bits: int = 8) -> None:
    """Write a float grey image in ``[0, 1]`` as an 8- or 16-bit file (format from the suffix).

    Values are rounded to the nearest level (``round(v * 255)`` or
    ``round(v * 65535)``), so a value ``k / 255`` written with ``bits=8`` reads
    back exactly.
    """
    if not cv2.imwrite(str(path), _levels(image, bits)):
        raise OSError(f"OpenCV could not write {path}")


def encode_image(image: np.ndarray, *, bits: int = 8, suffix: str = ".png") -> bytes:
    """The bytes of :func:`write_image`'s file (for atomic writes, :func:`bionav.files.write_atomic`)."""
    ok, data = cv2.imencode(suffix, _levels(image, bits))
    if not ok:
        raise OSError(f"OpenCV could not encode a {suffix} image")
    return data.tobytes()
