"""``python -m bionav --help``: every config group and its choices, listed once, then the config.

Hydra's own ``--help`` lists groups through one copy of its config repository per group
(about 120 deep copies of every stored config: seconds of CPU). bionav lists the groups it
owns directly instead: the YAML folders of every ``bionav.configs`` package and the plugin
groups of the entry points (:func:`bionav.registry.names_by_group`, no plugin imported but
the sensors), then composes the config once, with the command line's overrides, for the
``== Config ==`` part. Internal groups (``experiment_schema``, ``db_schema``) are not listed;
Hydra's groups (``hydra/launcher=...``) are in ``--hydra-help``.

:func:`composition_message` is the one paragraph users read when the command line does not
compose (a misspelt or moved key, a wrong type, an unknown option).
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


def _node_keys(overrides: list[str], node: str) -> list[str]:
    """Keys of config node ``node`` when composed with the group choices among ``overrides``."""
    from omegaconf import DictConfig, OmegaConf

    from bionav.config import compose

    groups = [o for o in overrides if "." not in o.split("=", 1)[0].lstrip("+~")]
    try:
        cfg = compose(groups)
    except Exception:
        return []
    value = OmegaConf.select(cfg, node) if node else cfg
    return [str(k) for k in value.keys()] if isinstance(value, DictConfig) else []


def composition_message(exc: BaseException, overrides: list[str]) -> str:
    """One paragraph for a Hydra composition error (misspelt key, wrong type, unknown option)."""
    from bionav.config import unknown_key_message

    cause = exc.__cause__ or exc.__context__
    full_key = str(getattr(cause, "full_key", "") or "")
    first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    name = type(cause).__name__ if cause is not None else ""
    if name in ("ConfigAttributeError", "ConfigKeyError") and full_key:
        if "." in full_key:
            node, bad = full_key.rsplit(".", 1)
        else:
            node, bad = "", full_key
        from bionav.experiments.settings import LEGACY_KEYS

        if full_key in LEGACY_KEYS:  # a setting that moved (one setting per quantity): say where to
            return (f"{full_key} is no longer a setting: it is {LEGACY_KEYS[full_key]} now (one setting per "
                    f"quantity); pass {LEGACY_KEYS[full_key]}=... instead.")
        message = unknown_key_message(node, bad, _node_keys(overrides, node))
        return f"{message} Fix the spelling on the command line (`python -m bionav --cfg job` shows the whole config)."
    if name == "ValidationError" and full_key:
        given = next((o.split("=", 1)[1] for o in overrides if o.split("=", 1)[0].lstrip("+~") == full_key), "?")
        reason = str(cause).splitlines()[0]
        return (f"bad value {full_key}={given}: {reason}. Give {full_key} a value of its declared type "
                f"(`python -m bionav --cfg job` shows the current value).")
    if type(exc).__name__ == "MissingConfigException":
        return (f"{first}. Pick one of the available options (`python -m bionav --help` lists them, "
                "`python -m bionav.plugins` the installed plugins).")
    return f"the configuration cannot be composed: {first}. Check the overrides on the command line."


#: Hydra plugins bionav documents, and the line that installs each (``hydra/<group>=<option>``)
HYDRA_PLUGIN_INSTALL = {
    "hydra/sweeper": {"optuna": 'pip install "bionav[tune]"', "nevergrad": "pip install hydra-nevergrad-sweeper",
                      "ax": "pip install hydra-ax-sweeper"},
    "hydra/launcher": {"joblib": 'pip install "bionav[parallel]"', "submitit_local": 'pip install "bionav[slurm]"',
                       "submitit_slurm": 'pip install "bionav[slurm]"', "ray": "pip install hydra-ray-launcher",
                       "rq": "pip install hydra-rq-launcher"},
}


def check_hydra_option(group: str, value: str) -> None:
    """Refuse ``hydra/<group>=<value>`` when no such Hydra plugin is installed, naming the line that installs it.

    Raises
    ------
    UserError
        With the installed options and, for a plugin bionav knows, its ``pip install`` line.
    """
    from bionav.config import hydra_group_options
    from bionav.errors import UserError

    available = hydra_group_options(group)
    if value in available or not available:
        return
    install = HYDRA_PLUGIN_INSTALL.get(group, {}).get(value)
    fix = (f"Install it with `{install}`, or pick an installed one" if install
           else "Pick an installed one, or install the Hydra plugin that provides it")
    raise UserError(f"{group}={value} is not installed (installed: {', '.join(available)}). {fix} "
                    f"(`python -m bionav --hydra-help` lists Hydra's groups).")
