"""What an experiment plugin is: a class with a typed ``Config`` and a ``run``.

An experiment is registered as an entry point of the group ``bionav.experiments``, like every
other kind of plugin (``bionav.homing``, ``bionav.sensors``, ...); bionav's own experiments are
registered the same way (``pyproject.toml``), one folder each, ``bionav/experiments/<name>/``:
``__init__.py`` (the plugin class), ``config.py`` (its dataclass with the ranges of its keys,
:func:`bionav.validation.bounded`), ``run.py``, ``plots.py`` and whatever further modules it
needs. ``python -m bionav experiment=<name>`` selects one: the runner
(:func:`bionav.experiments.runner.run_experiment`) takes the class from the registry, types
and checks the ``experiment`` node against ``Config`` before the run starts, constructs
``Cls(config)`` and calls ``run(ctx)``. A third-party experiment needs no YAML (its keys and
defaults come from ``Config``, as a homing plugin's); it may ship presets through
``bionav.configs`` (``experiment/<preset>.yaml``, docs/plugins.md).
"""

from __future__ import annotations

from typing import Any, ClassVar, Mapping

#: config groups that select plugins (the default of :attr:`Experiment.plugin_groups`: a run that does not
#: say which it reads records every selected one in run.mcap)
DEFAULT_PLUGIN_GROUPS = ("homing", "signature", "sensor", "pantilt", "controller", "decoder")


class Experiment:
    """Base class of experiment plugins (entry-point group ``bionav.experiments``).

    Class attributes
    ----------------
    Config : type
        The dataclass of the ``experiment.*`` keys (every field with a default and, for numbers and
        choices, a declared range: :func:`bionav.validation.bounded`). It may have a ``name`` field
        (the registry name); the runner checks a node against it before the run
        (:func:`bionav.validation.typed_config`: unknown keys, types, ranges, the ``unused_keys``
        and ``validate`` hooks).
    plugin_groups : tuple of str
        The config groups whose plugins a run reads (``homing``, ``signature``, ``sensor``,
        ``pantilt``, ``controller``, ``decoder``); run.mcap's ``plugins`` metadata names only
        these, so a compass run does not name the default ``homing=sift``.
    group_configs : dict
        Other top-level config nodes the run reads (``layout``, ``data``, ``recordings``) -> their
        dataclass; each node present is checked before the run starts. A preset may give a node
        its schema's defaults with ``- /experiment_nodes/<experiment>/<node>@<node>``.

    Attributes
    ----------
    config : Config
        The checked ``experiment`` node.
    """

    Config: ClassVar[type]
    plugin_groups: ClassVar[tuple[str, ...]] = DEFAULT_PLUGIN_GROUPS
    group_configs: ClassVar[Mapping[str, type]] = {}

    def __init__(self, config: Any) -> None:
        self.config = config

    @classmethod
    def used_plugin_groups(cls, node: Any) -> tuple[str, ...]:
        """The config groups whose plugins a run with the (unchecked) ``experiment`` node ``node`` reads.

        Default :attr:`plugin_groups`; an experiment whose use of a plugin depends on its keys
        overrides it (``route_homing`` homes with ``homing=`` only when ``homing`` is among its methods).
        """
        return cls.plugin_groups

    def run(self, ctx: Any) -> dict[str, Any]:
        """Run the experiment with :attr:`config` in ``ctx`` (:class:`bionav.experiments.context.RunContext`).

        Returns the run's metrics: a flat mapping of JSON values (metrics.json); write tables, plots
        (``ctx.plots``) and run.mcap messages (``ctx.log``) on the way.
        """
        raise NotImplementedError(f"{type(self).__name__} does not implement run(ctx)")
