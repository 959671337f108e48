"""``perfect_memory`` and ``windowed_memory`` route agents (Baddeley et al. 2012, doi:10.1371/journal.pcbi.1002336)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bionav.plugins.route_agents import RouteAgent
from bionav.validation import bounded


@dataclass
class PerfectMemoryConfig:
    """Perfect memory has no parameters: every training view is stored."""


class PerfectMemory(RouteAgent):
    """Unfamiliarity = the smallest mean squared pixel difference to any stored view."""

    Config = PerfectMemoryConfig

    def train(self, views: np.ndarray) -> None:
        self.snapshots = np.asarray(views, np.float64).reshape(len(views), -1)

    def unfamiliarity(self, views: np.ndarray) -> np.ndarray:
        from bionav.homing.familiarity import view_differences

        return view_differences(views, self.snapshots).min(axis=1)


@dataclass
class WindowedMemoryConfig:
    """Parameters of the windowed (sequential) perfect memory.

    Attributes
    ----------
    behind, ahead : int
        The views compared are ``behind`` before to ``ahead`` after the
        last best-matching view (route views, 0.1 m apart in the ardin2016 protocol).
    """

    behind: int = bounded(2, ge=0, le=10_000)
    ahead: int = bounded(10, ge=1, le=10_000)


class WindowedMemory(PerfectMemory):
    """Perfect memory restricted to a window of views around the last best match (starts at view 0)."""

    Config = WindowedMemoryConfig

    def train(self, views: np.ndarray) -> None:
        super().train(views)
        self.last = 0
        self._best = np.zeros(0, np.int64)

    def unfamiliarity(self, views: np.ndarray) -> np.ndarray:
        from bionav.homing.familiarity import view_differences

        lo = max(0, self.last - self.config.behind)
        hi = min(len(self.snapshots), self.last + self.config.ahead + 1)
        d = view_differences(views, self.snapshots[lo:hi])
        self._best = lo + np.argmin(d, axis=1)
        return d.min(axis=1)

    def choose(self, index: int) -> None:
        self.last = int(self._best[index])

    def reset(self, index: int) -> None:
        self.last = int(index)
