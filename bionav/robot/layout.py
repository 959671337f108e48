"""The cleaning layouts: ``layout=<name>`` (``bionav/conf/layout/*.yaml``, thesis fig. 7.2) as a :class:`LanePlan`.

Units: metres; angles in degrees only in keys ending ``_deg``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

from bionav.robot.controller import LanePlan
from bionav.validation import Range, bounded, typed_config


@dataclass
class LayoutConfig:
    """``layout=<name>`` of ``experiment=cleaning`` (``bionav/conf/layout/*.yaml``: thesis fig. 7.2).

    n_lanes, lane_length, spacing : the meander's lanes (m); unit_width : cleaning width (m).
    turn : side of the next lane seen from the first lane. wall_offset : first lane's distance from the
    wall on its right (m). start, start_heading_deg : ``[x, y]`` in the world (m) and heading; None:
    placed along a wall automatically.
    """

    name: str = "long_lanes"
    n_lanes: int = bounded(7, ge=1, le=1000)
    lane_length: float = bounded(4.0, gt=0.0, le=1000.0)
    spacing: float = bounded(0.30, gt=0.0, le=100.0)
    unit_width: float = bounded(0.30, gt=0.0, le=100.0)
    turn: str = bounded("left", choices=("left", "right"))
    wall_offset: float = bounded(0.25, ge=0.0, le=100.0)
    start: Optional[list[float]] = bounded(None, length=2, item=Range(ge=-1e4, le=1e4))
    start_heading_deg: Optional[float] = bounded(None, ge=-360.0, le=360.0)


def plan_from_layout(node: Any) -> LanePlan:
    """A :class:`LanePlan` from a ``layout`` config node (``bionav/conf/layout/*.yaml``), typed and checked
    as :class:`LayoutConfig` (:func:`bionav.validation.typed_config`)."""
    name = node.get("name", "?") if hasattr(node, "get") else getattr(node, "name", "?")
    layout = typed_config(node, LayoutConfig, key="layout", what=f"layout={name}")
    return LanePlan(n_lanes=layout.n_lanes, lane_length=layout.lane_length, spacing=layout.spacing,
                    turn=layout.turn, wall_offset=layout.wall_offset, unit_width=layout.unit_width)
