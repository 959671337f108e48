"""Homing algorithms as plain functions on arrays, and the plugin base class."""

from bionav.homing.base import HomeVector, HomingMethod

__all__ = ["HomeVector", "HomingMethod"]
