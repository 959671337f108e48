"""``controller=odometry``: the meander on odometry alone (the baseline of thesis chapter 7).

The first lane is driven by wall following like every meander; afterwards the
controller relies on dead reckoning only: lane changes, lane keeping and lane
ends all come from the odometry, which does not know the robot's wheel error.
"""

from __future__ import annotations

from dataclasses import dataclass

from bionav.robot.meander import MeanderConfig, MeanderController


@dataclass
class OdometryConfig(MeanderConfig):
    """Parameters of the odometry meander (see :class:`bionav.robot.meander.MeanderConfig`)."""


class OdometryController(MeanderController):
    """Meander controller without vision: lanes after the first are kept by odometry only."""

    Config = OdometryConfig
