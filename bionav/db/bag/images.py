"""Image messages of a ROS bag as grey float images, decoded as image files are.

``sensor_msgs/Image`` in ``mono8``, ``mono16``, ``rgb8``, ``bgr8`` (and
``8UC1``, ``16UC1``, ``rgba8``, ``bgra8``): the pixel buffer is read row by row
with the message's ``step`` (padding allowed) and byte order, colour converted
to grey with OpenCV's ITU-R BT.601 weights, 8-bit levels divided by 255 and
16-bit ones by 65535 (:func:`bionav.db.imageio.to_grey_float`).
``sensor_msgs/CompressedImage`` (``png``, ``jpeg``, also ``"mono16; png
compressed"`` and the other formats of ``compressed_image_transport``) is
decoded by :func:`bionav.db.imageio.decode_image`, the path of the image files
of ``db=folder``, so a view stored in a bag and the same view in a file give
the same float image bit for bit.

A message is kept undecoded (:class:`ImageMessage`, a reference to its
buffer) until it is known to be needed, so reading a bag decodes only the
views a database keeps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.errors import UserError

#: raw encodings: (dtype, channels, channel order)
RAW_ENCODINGS = {
    "mono8": ("u1", 1, None), "8UC1": ("u1", 1, None), "mono16": ("u2", 1, None), "16UC1": ("u2", 1, None),
    "rgb8": ("u1", 3, "rgb"), "bgr8": ("u1", 3, "bgr"), "8UC3": ("u1", 3, "bgr"),
    "rgba8": ("u1", 4, "rgb"), "bgra8": ("u1", 4, "bgr"),
}
COMPRESSED = "sensor_msgs/msg/CompressedImage"


@dataclass(frozen=True)
class ImageMessage:
    """One image message, not yet decoded.

    Attributes
    ----------
    stamp_ns : int
        Its stamp (``header.stamp`` or the bag's time, ``db.stamps``), ns since the epoch.
    index : int
        Its position on the topic (0-based), for messages.
    compressed : bool
        ``sensor_msgs/CompressedImage`` (else ``sensor_msgs/Image``).
    encoding : str
        ``encoding`` of a raw image, ``format`` of a compressed one.
    width, height : int
        Pixels (0 for compressed images until decoded).
    """

    stamp_ns: int
    index: int
    compressed: bool
    encoding: str
    width: int
    height: int
    step: int
    bigendian: bool
    data: object  # the message's byte buffer (a view; kept alive only while needed)

    @property
    def signature(self) -> tuple:
        """What must stay the same along one camera stream: kind, encoding and (raw) size."""
        return (self.compressed, self.encoding, self.width, self.height)

    def describe(self) -> str:
        kind = f"{self.encoding} compressed" if self.compressed else f"{self.encoding} {self.width} x {self.height}"
        return f"message {self.index} (stamp {self.stamp_ns / 1e9:.3f} s, {kind})"


def image_message(msg, msgtype: str, *, stamp_ns: int, index: int) -> ImageMessage:
    """The :class:`ImageMessage` of one deserialised ``Image`` / ``CompressedImage``."""
    if msgtype == COMPRESSED:
        return ImageMessage(stamp_ns, index, True, str(msg.format).strip(), 0, 0, 0, False, msg.data)
    return ImageMessage(stamp_ns, index, False, str(msg.encoding), int(msg.width), int(msg.height), int(msg.step),
                        bool(msg.is_bigendian), msg.data)


def check_encoding(m: ImageMessage, topic: str) -> None:
    """Refuse an encoding bionav cannot turn into a grey view (message names the supported ones)."""
    if m.compressed:
        if "compresseddepth" in m.encoding.lower().replace(" ", ""):
            raise UserError(f"{topic} carries depth images ({m.encoding!r}), not camera views; choose the camera's "
                            "image topic for db.image_topic.")
        return
    if m.encoding not in RAW_ENCODINGS:
        raise UserError(f"{topic}: {m.describe()} has the encoding {m.encoding!r}, which bionav does not read as a "
                        f"view; supported: {', '.join(RAW_ENCODINGS)} (or a CompressedImage topic in png or jpeg). "
                        "Republish the images in one of them (e.g. with image_proc) or choose another topic.")


def decode(m: ImageMessage, topic: str) -> np.ndarray:
    """Decode one image message into a float32 grey image ``(H, W)`` in ``[0, 1]``.

    Raises
    ------
    UserError
        A truncated buffer, an undecodable compressed image, an unsupported
        encoding; the message names the topic, the message and its stamp.
    """
    from bionav.db.imageio import ImageReadError, decode_image, to_grey_float

    check_encoding(m, topic)
    if m.compressed:
        try:
            return decode_image(np.asarray(m.data, dtype=np.uint8).tobytes())
        except ImageReadError as exc:
            raise UserError(f"{topic}: {m.describe()} cannot be decoded ({exc}); record the bag again or leave such "
                            "images out with db.on_bad_image=skip.") from None
    code, channels, order = RAW_ENCODINGS[m.encoding]
    dtype = np.dtype(code).newbyteorder(">" if m.bigendian else "<")
    row_bytes = m.width * channels * dtype.itemsize
    buf = np.asarray(m.data, dtype=np.uint8).reshape(-1)
    if m.width < 1 or m.height < 1 or m.step < row_bytes or buf.size < m.step * m.height:
        raise UserError(f"{topic}: {m.describe()} is malformed (step {m.step} bytes for rows of {row_bytes}, "
                        f"{buf.size} of {m.step * m.height} data bytes); record the bag again or leave such images "
                        "out with db.on_bad_image=skip.")
    rows = buf[: m.step * m.height].reshape(m.height, m.step)[:, :row_bytes]
    pixels = np.ascontiguousarray(rows).view(dtype).astype(dtype.newbyteorder("="), copy=False)
    image = pixels.reshape(m.height, m.width, channels) if channels > 1 else pixels.reshape(m.height, m.width)
    if order == "rgb":  # OpenCV's grey conversion takes BGR(A)
        image = np.ascontiguousarray(image[..., [2, 1, 0, 3][:channels]])
    return to_grey_float(image)
