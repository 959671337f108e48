"""Ranges shared by several experiments' configs (declared once, used with ``bounded(default, **RANGE)``)."""

from __future__ import annotations

#: agent step length, grid units (thesis 3.2.3: 0.5)
STEP = dict(gt=0.0, le=10.0)
#: success radius, grid units (thesis: 1.0)
RADIUS = dict(gt=0.0, le=100.0)
