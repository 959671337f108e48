"""``random_choice`` route agent: the random-choice baseline of Ardin et al. 2016 (doi:10.1371/journal.pcbi.1004683, Fig. 4D)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.plugins.route_agents import RouteAgent


@dataclass
class RandomChoiceConfig:
    """The random-choice baseline has no parameters: every heading of the scan is equally likely."""


class RandomChoice(RouteAgent):
    """A heading drawn uniformly from the scan at every step, whatever the agent sees.

    The baseline the published figure compares the route memories with (Ardin et al. 2016,
    Fig. 4D, "random choice of direction"): each step the agent walks along one of the
    ``S`` scan headings (``+-scan_half_deg`` in ``scan_step_deg``), each with probability
    ``1 / S``, drawn from the run's random stream. It needs no views (``needs_views = False``:
    the follower renders nothing for it) and learns nothing.
    """

    Config = RandomChoiceConfig
    needs_views = False

    def train(self, views: np.ndarray) -> None:
        """Nothing to learn."""

    def unfamiliarity(self, views: np.ndarray) -> np.ndarray:
        """Independent uniform values in [0, 1), one per candidate (ties have probability 0)."""
        return self.rng.random(len(views))
