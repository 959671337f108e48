"""Serial-port plumbing shared by bionav's device drivers (pyserial with timeouts and clear errors)."""

from bionav.serialio.port import SerialLink

__all__ = ["SerialLink"]
