"""The run's objective: the one number a Hydra sweeper (Optuna, Nevergrad, ...) optimises.

The config names it::

    objective:
      metric: aae          # a metrics.json key; nested objects as a.b (e.g. J.all)
      direction: minimize  # or maximize

Every experiment sets a default (``aae``/minimize for homing, ``coverage``/maximize for
cleaning, ...); ``objective.metric=rr objective.direction=maximize`` picks another one. A job
that fails, or whose metric is missing or not finite, returns the *worst* value of its
direction: ``+inf`` when minimising, ``-inf`` when maximising, so a sweeper ranks it last and
never mistakes a crash for a good result (Optuna records such trials as completed with that
value; NaN would make it drop them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from bionav.errors import UserError
from bionav.validation import bounded, typed_config

DIRECTIONS = ("minimize", "maximize")


@dataclass(frozen=True)
class Objective:
    """Which metric a sweep optimises and in which direction.

    Attributes
    ----------
    metric : str
        Key of metrics.json; nested objects are addressed as ``a.b``.
    direction : str
        ``minimize`` or ``maximize``.
    """

    metric: str
    direction: str = bounded("minimize", choices=DIRECTIONS)

    def validate(self) -> None:
        """A metric name is given (called by :func:`bionav.validation.typed_config`)."""
        if self.metric.strip() == "":
            raise UserError("objective.metric is empty; name a metrics.json key, e.g. objective.metric=aae.")

    @property
    def worst(self) -> float:
        """The value a failed job returns: ``+inf`` when minimising, ``-inf`` when maximising."""
        return math.inf if self.direction == "minimize" else -math.inf

    def value(self, metrics: Mapping[str, Any] | None) -> float:
        """The objective's value in a run's metrics; :attr:`worst` if failed, missing or not finite."""
        if not metrics or metrics.get("status") == "failed":
            return self.worst
        node: Any = metrics
        for part in self.metric.split("."):
            if not isinstance(node, Mapping) or part not in node:
                node = metrics.get(self.metric) if isinstance(metrics, Mapping) else None
                break
            node = node[part]
        try:
            value = float(node)
        except (TypeError, ValueError):
            return self.worst
        return value if math.isfinite(value) else self.worst


def objective_from_config(node: Any) -> Objective | None:
    """The :class:`Objective` of a config's ``objective`` node (None if the config has none).

    Raises
    ------
    UserError
        For a direction other than ``minimize``/``maximize`` or a missing or empty metric name
        (:func:`bionav.validation.typed_config`).
    """
    if node is None:
        return None
    return typed_config(node, Objective, key="objective")
