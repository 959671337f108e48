"""Shared fixtures: fake installed distributions for registry tests, small rendered databases."""

from __future__ import annotations

import sys
import textwrap

import pytest


@pytest.fixture
def fake_distributions(tmp_path, monkeypatch):
    """Install fake distributions (dist-info + module) on a temporary sys.path entry.

    Returns a function ``add(dist_name, entry_points: dict[group, dict[name, target]], module_source: dict[modname, source])``.
    """
    from bionav import registry

    root = tmp_path / "site"
    root.mkdir()
    monkeypatch.syspath_prepend(str(root))
    registry.clear_cache()

    def add(dist: str, entry_points: dict, modules: dict | None = None, version: str = "1.0") -> None:
        info = root / f"{dist.replace('-', '_')}-{version}.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
        lines = []
        for group, eps in entry_points.items():
            lines.append(f"[{group}]")
            lines += [f"{name} = {target}" for name, target in eps.items()]
        (info / "entry_points.txt").write_text("\n".join(lines) + "\n")
        for modname, source in (modules or {}).items():
            (root / f"{modname}.py").write_text(textwrap.dedent(source))
        registry.clear_cache()

    yield add
    registry.clear_cache()
    for name in list(sys.modules):
        if name.startswith("fakeplug"):
            del sys.modules[name]


CONTROLLERS = {
    "triangulation": "bionav.plugins.controllers.triangulation:TriangulationController",
    "odometry": "bionav.plugins.controllers.odometry:OdometryController",
    "random": "bionav.plugins.controllers.random_bounce:RandomController",
}


@pytest.fixture
def controllers(fake_distributions):
    """The built-in controllers, registered by a stand-in distribution when bionav is not installed."""
    from bionav import registry

    if not set(CONTROLLERS) <= set(registry.entry_points_of("controller")):
        fake_distributions("bionav-controllers-dev", {"bionav.controllers": CONTROLLERS})
