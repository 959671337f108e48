"""``python -m bionav.plugins``: every registered plugin per kind, and those that failed to load."""

from __future__ import annotations

import sys
import warnings


def main() -> int:
    from bionav import registry
    from bionav.errors import PluginError

    broken = []
    for kind in registry.GROUPS:
        print(f"{kind}:")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                loaded = registry.plugins_of(kind, warn=False)
        except PluginError as exc:
            print(f"  error: {exc}")
            broken.append(kind)
            continue
        if not loaded:
            print("  (none)")
        for name, plugin in sorted(loaded.items()):
            e = plugin.entry
            if kind in registry.KINDS_WITHOUT_GROUP:
                select = registry.KINDS_WITHOUT_GROUP[kind].format(name=name)
            else:
                select = " ".join(f"{group}={name}" for group in plugin.config_groups)
            state = "ok" if plugin.cls is not None else "FAILED"
            print(f"  {select:28s} {e.distribution} {e.version:10s} {state}")
            if plugin.error:
                print(f"      {plugin.error}")
                broken.append(name)
    configs = registry.config_packages()
    print("config packages:")
    for name, package, dist in configs:
        print(f"  {name:28s} {package} ({dist})")
    if broken:
        print(f"\n{len(broken)} plugin(s) failed to load; they are skipped unless selected.", file=sys.stderr)
    return 0


if __name__ == "__main__":
    from bionav.cli_main import run_main

    run_main(main, "bionav.plugins")
