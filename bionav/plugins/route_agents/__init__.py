"""bionav's built-in ``bionav.route_agents`` plugins: scene-familiarity route followers.

Each agent is trained on the views along a route and rates the views of a scan
by their unfamiliarity (lower = more familiar); ``experiment=route_homing
experiment.protocol=ardin2016`` walks it along the least unfamiliar heading
(docs/worlds.md). The contract (:class:`RouteAgent`):

* ``Config``: a dataclass of the agent's parameters (ranges via ``bounded``);
* ``__init__(config, *, rng)``: ``rng`` is the run's :class:`numpy.random.Generator`
  (random connectivity, initial weights);
* ``train(views)``: ``views`` shape ``(K, H, W)``, the route's views in order;
* ``unfamiliarity(views)`` -> shape ``(S,)``: one value per candidate view;
* ``choose(s)``: the agent walked along candidate ``s`` of the last call (sequence state);
* ``reset(index)``: the agent was put back at route view ``index``;
* ``needs_views`` (class attribute, default True): False for an agent that ignores what it sees
  (``random_choice``), whose follower renders nothing and hands it ``S`` empty views.

The algorithms are plain functions in :mod:`bionav.homing.familiarity`.
"""

from __future__ import annotations

from typing import Any

import numpy as np


class RouteAgent:
    """Base of the familiarity route agents (stateless choose/reset by default)."""

    Config: Any = None
    #: False: the agent ignores the views (the follower passes ``(S, 0)`` empty views, rendering nothing)
    needs_views: bool = True

    def __init__(self, config, *, rng: np.random.Generator) -> None:
        self.config = config
        self.rng = rng

    def train(self, views: np.ndarray) -> None:  # pragma: no cover - the contract
        raise NotImplementedError

    def unfamiliarity(self, views: np.ndarray) -> np.ndarray:  # pragma: no cover - the contract
        raise NotImplementedError

    def choose(self, index: int) -> None:
        """The agent walked along candidate ``index`` of the last :meth:`unfamiliarity` call."""

    def reset(self, index: int) -> None:
        """The agent was put back at route view ``index``."""
