"""docs/plugins.md: every Python snippet runs (in order, one namespace) and its checks hold."""

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "plugins.md"


def _snippets() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.DOTALL)


def _package_classes() -> dict[str, set[str]]:
    """Module -> the classes it defines, of the packages this page writes out as ``file=`` blocks."""
    import ast

    from helpers import DOCS_FILE_BLOCK

    out: dict[str, set[str]] = {}
    for path, text in DOCS_FILE_BLOCK.findall(DOC.read_text()):
        if path.endswith(".py"):
            module = ".".join(path.split("/")[1:]).removesuffix(".py").removesuffix(".__init__")
            out[module] = {n.name for n in ast.parse(text).body if isinstance(n, ast.ClassDef)}
    return out


def test_plugin_docs_snippets_run():
    snippets = _snippets()
    assert len(snippets) == 12  # a plugin and its test, per kind
    namespace: dict = {"__name__": "docs_plugins"}
    for snippet in snippets:
        exec(compile(snippet, str(DOC), "exec"), namespace)
    # the documented plugins pass bionav's own contract checks
    from bionav.config import plugin_node_class
    from bionav.testing import assert_homing_plugin

    assert_homing_plugin(namespace["DarkCentroidHoming"])
    for cls in ("DarkCentroidHoming", "RowMax", "NoisyCounter", "StraightController", "BrightSide", "NearestView"):
        plugin_node_class("x", namespace[cls].Config)  # Hydra can store every Config


def test_plugin_docs_example_rejects_bad_values():
    namespace: dict = {"__name__": "docs_plugins"}
    exec(compile(_snippets()[0], str(DOC), "exec"), namespace)
    import pytest

    from bionav.errors import UserError
    from bionav.geometry import PanoramaGeometry

    cls = namespace["DarkCentroidHoming"]
    with pytest.raises(UserError, match="homing.band_deg"):
        cls(cls.Config(band_deg=0.0), geometry=PanoramaGeometry.square_pixels(64, 16))


def test_render_pillar_panorama_is_exported():
    import bionav.testing

    assert "render_pillar_panorama" in bionav.testing.__all__
    image, geometry = bionav.testing.render_pillar_panorama((0.0, 0.0), width=32, height=8, supersample=1)
    assert image.shape == (8, 32) and (geometry.width, geometry.height) == (32, 8)


def test_plugin_docs_decoder_rejects_bad_values_through_its_config():
    namespace: dict = {"__name__": "docs_plugins"}
    exec(compile(next(s for s in _snippets() if "class BrightSide" in s), str(DOC), "exec"), namespace)
    import pytest

    from bionav.errors import UserError
    from bionav.validation import check_config

    cls = namespace["BrightSide"]
    assert check_config(cls.Config(min_contrast=0.05), prefix="decoder").min_contrast == 0.05
    with pytest.raises(UserError, match="decoder.min_contrast"):
        check_config(cls.Config(min_contrast=2.0), prefix="decoder")


def test_plugin_docs_complete_pyproject_names_the_documented_plugins():
    import tomllib

    from bionav.registry import CONFIG_GROUP, GROUPS

    blocks = re.findall(r"```toml\n(.*?)```", DOC.read_text(), flags=re.DOTALL)
    full = [tomllib.loads(b) for b in blocks if "[build-system]" in b]
    assert len(full) == 1
    project = full[0]["project"]
    assert project["name"] and project["version"] and "bionav" in project["dependencies"]
    eps = project["entry-points"]
    assert set(eps) == {*GROUPS.values(), CONFIG_GROUP}  # one plugin of every kind, and presets
    namespace: dict = {"__name__": "docs_plugins"}
    for snippet in _snippets():
        exec(compile(snippet, str(DOC), "exec"), namespace)
    packages = _package_classes()  # the experiment's package, written out file by file
    for group, entries in eps.items():
        for name, target in entries.items():
            module, _, attr = target.partition(":")
            if module in packages:
                assert attr in packages[module], f"{group} {name} = {target}: no such class in {module}"
                continue
            assert module.startswith("my_package"), target
            if group != CONFIG_GROUP:
                assert attr in namespace, f"{group} {name} = {target}: no such class in the snippets"
                # the short registration line of each section names the same target
                assert f'{name} = "{target}"' in DOC.read_text().split("## A complete")[0], target
