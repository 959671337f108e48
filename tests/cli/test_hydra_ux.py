"""Hydra UX: --help lists each config group once; bash completion works for `python -m bionav`."""

import json
import os
import re
import shutil
import subprocess
import sys

import pytest
from helpers import run_bionav


def _groups(help_text: str) -> list[str]:
    section = help_text.split("== Configuration groups ==", 1)[1].split("== Config ==", 1)[0]
    return [m.group(1) for m in re.finditer(r"^([\w/.-]+): ", section, re.MULTILINE)]


def test_help_lists_each_group_once(tmp_path):
    proc = run_bionav("--help", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    groups = _groups(proc.stdout)
    assert len(groups) == len(set(groups)), groups
    assert not [g for g in groups if "/" in g], groups  # no conf/... duplicates
    assert {"experiment", "db", "homing", "signature", "preprocess"} <= set(groups)


def test_primary_search_path_is_bionavs_config_folder(tmp_path):
    proc = run_bionav("--info", "searchpath", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    # the folder of the bionav that `python -m bionav` imports outside the checkout (the installed
    # package; the test process itself may import the source tree)
    own = subprocess.run([sys.executable, "-c", "from bionav.config import config_dirs; "
                          "print(dict(config_dirs())['bionav'])"], cwd=tmp_path, capture_output=True,
                         text=True, timeout=120, check=True).stdout.strip()
    rows = [line for line in proc.stdout.splitlines() if "file://" in line or "pkg://" in line]
    assert any(re.search(rf"\|\s*main\s*\|\s*file://{re.escape(str(own))}\s*\|", r) for r in rows), rows
    assert sum(str(own) in r for r in rows) == 1, rows  # searched once
    assert not any("pkg://bionav" in r for r in rows), rows


def _complete(line: str, tmp_path) -> list[str]:
    env = dict(os.environ, COMP_LINE=line, COMP_POINT=str(len(line)), BIONAV_CACHE=str(tmp_path / "cache"))
    proc = subprocess.run([sys.executable, "-m", "bionav", "-sc", "query=bash"], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.split()


@pytest.mark.slow
def test_completion_query_for_python_m_bionav(tmp_path):
    assert _complete("python -m bionav homing=m", tmp_path) == [
        "homing=mfdid", "homing=minwarping", "homing=minwarping_cleaning", "homing=minwarping_thesis"]
    groups = [c for c in _complete("python -m bionav ", tmp_path) if c.endswith("=") and "." not in c]
    assert len(groups) == len(set(groups)) and not [g for g in groups if "/" in g]
    assert "experiment=" in groups and "signature=" in groups
    assert _complete("python3 -m bionav homing.search_r", tmp_path) == ["homing.search_radius="]


@pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")
def test_installed_bash_completion_completes_python_m_bionav(tmp_path):
    script = run_bionav("-sc", "install=bash", cwd=tmp_path)
    assert script.returncode == 0, script.stderr
    line = f"{sys.executable} -m bionav db=sim_ha"
    driver = (
        f'{script.stdout}\n'
        f'COMP_LINE="{line}"; COMP_POINT=${{#COMP_LINE}}; COMP_CWORD=3\n'
        f'_bionav_completion\nprintf "%s\\n" "${{COMPREPLY[@]}}"\n'
    )
    proc = subprocess.run(["bash", "-c", driver], capture_output=True, text=True, timeout=120, cwd=tmp_path,
                          env=dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache")))
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["db=sim_hall1", "db=sim_hall2"]


def _imported_modules(args: list[str], tmp_path, *, comp_line: str | None = None,
                      stdout: list[str] | None = None) -> set[str]:
    """Modules imported by bionav's command line ``ARGS`` (run in a fresh interpreter).

    ``comp_line``: the shell's COMP_LINE of a completion query; ``stdout``: receives the output.
    """
    out = tmp_path / "modules.json"
    code = ("import json, sys\nfrom bionav.cli import main\ntry:\n    main(%r)\nexcept SystemExit as exc:\n"
            "    assert not exc.code, exc.code\nopen(%r, 'w').write(json.dumps(sorted(sys.modules)))\n"
            % (list(args), str(out)))
    env = dict(os.environ, BIONAV_CACHE=str(tmp_path / "cache"))
    if comp_line is not None:
        env.update(COMP_LINE=comp_line, COMP_POINT=str(len(comp_line)))
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    if stdout is not None:
        stdout.append(proc.stdout)
    return set(json.loads(out.read_text()))


def test_plugins_are_imported_only_when_selected(tmp_path):
    """Issue 28 item 3: entry points are listed without importing plugin modules."""
    listed = _imported_modules(["--help"], tmp_path)  # lists every plugin, shows the default config (sift)
    plugins = {m for m in listed if m.startswith(("bionav.plugins.homing.", "bionav.plugins.signatures.",
                                                   "bionav.plugins.controllers.", "bionav.plugins.decoders."))}
    assert plugins == {"bionav.plugins.homing.sift"}, plugins
    composed = _imported_modules(["homing=mfdid", "--cfg", "job"], tmp_path)
    assert "bionav.plugins.homing.mfdid" in composed
    assert "bionav.plugins.homing.sift" not in composed and "bionav.plugins.homing.warping" not in composed


def test_a_key_completion_composes_without_other_plugins_or_numpy_free_rooms(tmp_path):
    """TAB after a key composes the default config: only the selected plugin (sift) is imported; no sensor
    plugin (Hydra asks for ``sensor/None``), no database room (its schema is read without NumPy's users)."""
    printed: list[str] = []
    modules = _imported_modules(["-sc", "query=bash"], tmp_path, comp_line="python -m bionav homing.search_r",
                                stdout=printed)
    assert printed[0].split() == ["homing.search_radius="]
    plugins = {m for m in modules if m.startswith("bionav.plugins.") and m.count(".") >= 3}
    assert plugins == {"bionav.plugins.homing.sift"}, plugins
    assert "bionav.db.database" not in modules and "bionav.experiments.grid_homing.run" not in modules


@pytest.mark.slow
def test_internal_groups_are_not_offered(tmp_path):
    proc = run_bionav("--help", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "experiment_schema" not in proc.stdout and "db_schema" not in proc.stdout
    assert not [c for c in _complete("python -m bionav ", tmp_path) if "schema" in c]
    assert _complete("python -m bionav pantilt=", tmp_path) == ["pantilt=ptu46", "pantilt=replay", "pantilt=sim"]


@pytest.mark.slow
def test_help_shows_the_config_of_the_overrides_and_refuses_bad_ones(tmp_path):
    proc = run_bionav("homing=mfdid", "--help", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    config = proc.stdout.split("== Config ==", 1)[1]
    assert "name: mfdid" in config and "name: sift" not in config
    bad = run_bionav("homing=nope", "--help", cwd=tmp_path)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "homing/nope" in bad.stderr
