"""``experiment=route_homing``: following real ant routes in a mesh world (Seville 2009 by default)."""

from __future__ import annotations

from typing import Any

from bionav.experiments.base import Experiment
from bionav.experiments.route_homing.config import RouteHomingConfig


class RouteHoming(Experiment):
    """Route following: bionav's open- and closed-loop tests, or the published protocol (``experiment.protocol``)."""

    Config = RouteHomingConfig
    plugin_groups = ("homing",)

    @classmethod
    def used_plugin_groups(cls, node: Any) -> tuple[str, ...]:
        """``homing=`` is used only with ``homing`` among ``experiment.methods``."""
        methods = list(node.get("methods") or []) if node is not None and hasattr(node, "get") else []
        return cls.plugin_groups if "homing" in methods else ()

    @staticmethod
    def merge(task_dirs, out) -> dict[str, Any]:
        """Join the tasks (``experiment.block=[i,n]``) of one split ``ardin2016`` run into ``out``
        (``python -m bionav.experiments.merge``)."""
        from bionav.experiments.route_homing.merge import merge

        return merge(task_dirs, out)

    def run(self, ctx) -> dict[str, Any]:
        if self.config.protocol == "ardin2016":
            from bionav.experiments.route_homing.ardin2016 import run
        else:
            from bionav.experiments.route_homing.run import run
        return run(self.config, ctx)
