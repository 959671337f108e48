"""``python -m bionav --help``: every config group and its choices, listed once, then the config.

Hydra's own ``--help`` lists groups through one copy of its config repository per group
(about 120 deep copies of every stored config: seconds of CPU). bionav lists the groups it
owns directly instead: the YAML folders of every ``bionav.configs`` package and the plugin
groups of the entry points (:func:`bionav.registry.names_by_group`, no plugin imported but
the sensors), then composes the config once, with the command line's overrides, for the
``== Config ==`` part. Internal groups (``experiment_schema``, ``db_schema``) are not listed;
Hydra's groups (``hydra/launcher=...``) are in ``--hydra-help``.
"""

from __future__ import annotations

from typing import Sequence

#: flags that ask for this help
HELP_FLAGS = ("--help", "-h")


def wants_help(argv: Sequence[str]) -> bool:
    """True when the command line asks for bionav's help (``--help`` / ``-h``)."""
    return any(a in HELP_FLAGS for a in argv)


def groups_and_options(only: str | None = None) -> dict[str, list[str]]:
    """Config group -> sorted choices: YAML presets of every config package and plugin names.

    Parameters
    ----------
    only : str, optional
        Just this group (fast: plugins of other groups are not looked at).
    """
    from bionav import registry

    groups: dict[str, set[str]] = {}
    for _name, folder in registry.config_dirs():
        subs = [folder / only] if only else sorted(folder.iterdir())
        for sub in subs:
            if sub.is_dir() and not sub.name.startswith(("_", ".")):
                options = {p.stem for p in sub.glob("*.yaml")}
                if options:
                    groups.setdefault(sub.name, set()).update(options)
    plugin_groups = {only: registry.names_in_group(only)} if only else registry.names_by_group()
    for group, names in plugin_groups.items():
        if names:
            groups.setdefault(group, set()).update(names)
    return {group: sorted(options) for group, options in sorted(groups.items())}


def help_text(overrides: Sequence[str]) -> str:
    """The whole help page for a command line's ``overrides`` (header, groups, config, footer)."""
    from omegaconf import OmegaConf

    from bionav.config import compose

    cfg = compose([o for o in overrides if not o.startswith("-")], return_hydra_config=True)
    header = str(cfg.hydra.help.get("header", "")).rstrip("\n")
    footer = str(cfg.hydra.help.get("footer", "")).rstrip("\n")
    job = OmegaConf.to_container(cfg, resolve=False)
    job.pop("hydra", None)
    lines = [header, "", "== Configuration groups ==", "Compose your configuration from those groups (group=option)", ""]
    lines += [f"{group}: {', '.join(options)}" for group, options in groups_and_options().items()]
    lines += ["", "", "== Config ==", "Override anything in the config (foo.bar=value)", "",
              OmegaConf.to_yaml(OmegaConf.create(job)).rstrip("\n"), "", footer]
    return "\n".join(lines) + "\n"
