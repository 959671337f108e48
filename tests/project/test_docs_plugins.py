"""docs/plugins.md: every Python snippet runs (in order, one namespace) and its checks hold."""

import re
from pathlib import Path

import pytest

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

    assert_homing_plugin(namespace["HorizonWarpHoming"])
    for cls in ("HorizonWarpHoming", "RowMax", "NoisyCompass", "StraightController", "BrightSide", "NearestView"):
        plugin_node_class("x", namespace[cls].Config)  # Hydra can store every Config


def test_plugin_docs_example_rejects_bad_values():
    namespace: dict = {"__name__": "docs_plugins"}
    exec(compile(_snippets()[0], str(DOC), "exec"), namespace)
    import pytest

    from bionav.errors import UserError
    from bionav.geometry import PanoramaGeometry

    cls = namespace["HorizonWarpHoming"]
    with pytest.raises(UserError, match="homing.band_deg"):
        cls(cls.Config(band_deg=0.0), geometry=PanoramaGeometry.square_pixels(64, 16))
    with pytest.raises(UserError, match=r"homing.directions=2: .*>= 4 and <= 720"):
        cls(cls.Config(directions=2), geometry=PanoramaGeometry.square_pixels(64, 16))


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


def _install_docs_plugins(site):
    """The page's homing method and sensor as an installed distribution (entry points as the page registers them)."""
    from helpers import install_plugin_dist

    snippets = _snippets()
    homing = next(s for s in snippets if "class HorizonWarpHoming" in s)
    sensor = next(s for s in snippets if "class NoisyCompass" in s)
    return install_plugin_dist(site, "my-bionav-plugins", {
        "bionav.homing": {"horizon_warp": "my_homing:HorizonWarpHoming"},
        "bionav.sensors": {"noisy_compass": "my_sensors:NoisyCompass"}}, {"my_homing": homing, "my_sensors": sensor})


def test_the_docs_homing_example_refuses_a_bad_range_before_the_run(tmp_path):
    """`homing=horizon_warp homing.directions=2`: its `bounded` range refuses the value before Hydra makes a run
    directory, one message naming the key and the range (issue 39: the check used to come after the start)."""
    from helpers import assert_fails_cleanly, pythonpath_with, run_bionav

    site = _install_docs_plugins(tmp_path / "site")
    proc = run_bionav("homing=horizon_warp", "homing.directions=2", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path,
                      env=pythonpath_with(site))
    assert_fails_cleanly(proc, "homing.directions=2", ">= 4 and <= 720", code=2)
    assert not (tmp_path / "run").exists()


@pytest.mark.slow
def test_the_docs_homing_example_homes_better_than_chance_on_the_default_database(tmp_path):
    """`python -m bionav homing=horizon_warp` as the page shows it (issue 45: the earlier example scored AAE* 2.28)."""
    import json

    from helpers import pythonpath_with, run_bionav

    from bionav.files import default_cache_dir

    site = _install_docs_plugins(tmp_path / "site")
    env = {**pythonpath_with(site), "BIONAV_CACHE": str(default_cache_dir())}  # the shared render of sim_original
    proc = run_bionav("homing=horizon_warp", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    metrics = json.loads((tmp_path / "run" / "metrics.json").read_text())
    # a guess scores AAE* pi/2 and RR* about 0.02 here; the page states AAE* 0.47 rad, RR* 0.81
    assert metrics["aae"] < 0.7 and metrics["rr"] > 0.6, metrics


@pytest.mark.slow
def test_the_docs_sensor_example_runs_in_the_named_experiment(tmp_path):
    """`experiment=pol_compass mode=rotation sensor=noisy_compass` as the page shows it: completed, and its
    heading errors grow with the board noise; a sensor with other readings is refused before the session."""
    import json

    from helpers import assert_fails_cleanly, pythonpath_with, run_bionav

    site = _install_docs_plugins(tmp_path / "site")
    env = pythonpath_with(site)
    rmse = {}
    for noise in (0, 8):
        run_dir = tmp_path / f"noise{noise}"
        proc = run_bionav("experiment=pol_compass", "mode=rotation", "sensor=noisy_compass",
                          f"sensor.extra_noise_counts={noise}", f"hydra.run.dir={run_dir}", cwd=tmp_path, env=env)
        assert proc.returncode == 0, proc.stderr
        metrics = json.loads((run_dir / "metrics.json").read_text())
        assert metrics["status"] == "completed"
        rmse[noise] = metrics["heading_rmse_deg"]
    assert rmse[0] < 3.0 < rmse[8], rmse
    proc = run_bionav("experiment=pol_compass", "mode=rotation", "sensor=spectral5_sim",
                      f"hydra.run.dir={tmp_path / 'wrong'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "sensor=spectral5_sim", "experiment=pol_compass reads bionav.PolCompassReading",
                         code=2)
    assert not (tmp_path / "wrong").exists()
