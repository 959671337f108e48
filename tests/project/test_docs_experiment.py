"""An experiment out of tree: the package of docs/plugins.md ("Experiments") built from the page, installed into
a fresh virtual environment, run by the page's own commands through ``python -m bionav``, as a sweep, and
reported (issue 39). No edit to bionav: the package is found through its ``bionav.experiments`` entry point."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
from helpers import REPO, docs_packages, write_docs_package

DOC = REPO / "docs" / "plugins.md"
PACKAGE = "bionav-catchment"


def _documented_commands() -> list[list[str]]:
    """The shell commands of the Experiments section's block that installs the package (comments dropped)."""
    section = DOC.read_text().split("## Experiments", 1)[1].split("\n## ", 1)[0]
    block = next(b for b in section.split("```bash\n")[1:] if f"pip install -e {PACKAGE}" in b).split("```")[0]
    return [shlex.split(line.split("  #")[0]) for line in block.splitlines() if line.strip()]


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    """A fresh virtual environment that sees this bionav (a ``.pth`` adds the running environment's
    site-packages, editable installs included) and has the docs' package installed into it by pip."""
    root = tmp_path_factory.mktemp("docs_experiment")
    src = write_docs_package(PACKAGE, root / "src")
    env_dir = root / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(env_dir)], check=True)
    python = env_dir / "bin" / "python"
    site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    (site / "_bionav_under_test.pth").write_text(f"import site; site.addsitedir({sysconfig.get_paths()['purelib']!r})\n")
    proc = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
                           "--target", str(site), str(src)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return python, root


def _run(python, root, args, **kwargs):
    env = dict(os.environ, BIONAV_CACHE=str(root / "cache"), MPLBACKEND="Agg")
    return subprocess.run([str(python), "-m", *args], cwd=root, env=env, capture_output=True, text=True,
                          timeout=600, **kwargs)


def test_the_page_writes_out_a_whole_package():
    files = docs_packages()[PACKAGE]
    assert {"pyproject.toml", "bionav_catchment/__init__.py", "bionav_catchment/config.py", "bionav_catchment/run.py",
            "bionav_catchment/plots.py", "bionav_catchment/conf/experiment/catchment_wide.yaml"} <= set(files)
    commands = _documented_commands()
    assert commands[0][:3] == ["pip", "install", "-e"] and commands[0][3] == PACKAGE
    assert any(c[:3] == ["python", "-m", "bionav"] and "-m" not in c[3:] for c in commands)
    assert any(c[:4] == ["python", "-m", "bionav", "-m"] for c in commands)
    assert any(c[:3] == ["python", "-m", "bionav.report"] for c in commands)


@pytest.mark.slow
def test_an_installed_experiment_runs_sweeps_and_reports_with_no_edit_to_bionav(venv):
    from bionav.logs.reader import read_messages, read_metadata

    python, root = venv
    commands = [c[2:] for c in _documented_commands() if c[:2] == ["python", "-m"]]
    single = [c for c in commands if c[0] == "bionav" and "-m" not in c]
    sweep = next(c for c in commands if c[:2] == ["bionav", "-m"])
    report = next(c for c in commands if c[0] == "bionav.report")

    # selectable with no YAML: listed by --help, its keys composed from its typed config
    proc = _run(python, root, ["bionav", "--help"])
    assert proc.returncode == 0 and "catchment" in next(l for l in proc.stdout.splitlines() if l.startswith("experiment:"))
    for k, args in enumerate(single):  # the page's single runs
        run_dir = root / "runs" / str(k)
        proc = _run(python, root, [*args, f"hydra.run.dir={run_dir}"])
        assert proc.returncode == 0, proc.stderr[-2000:]
        metrics = json.loads((run_dir / "metrics.json").read_text())
        assert metrics["status"] == "completed" and metrics["experiment"] == "catchment"
        assert 0 <= metrics["aae"] <= 3.1416 and 0 <= metrics["success"] <= 1
        rows = (run_dir / "catchment.csv").read_text().splitlines()
        assert rows[0] == "radius_m,x_m,y_m,angle,error" and len(rows) == 1 + metrics["n_views"]
        assert (run_dir / "plots" / "catchment.png").stat().st_size > 1000
        messages = [m for _, _, m in read_messages(run_dir / "run.mcap", topics=["/catchment/home_vector"])]
        assert len(messages) == metrics["n_views"]
        mean_error = sum(m["error"] for m in messages) / len(messages)
        assert abs(mean_error - metrics["aae"]) < 1e-12  # the metric is the logged errors' mean
        plugins = read_metadata(run_dir / "run.mcap")["plugins"]
        assert set(plugins) == {"bionav", "homing"}  # plugin_groups: only the homing method it reads
    views = [json.loads((root / "runs" / str(k) / "metrics.json").read_text())["n_views"] for k in range(len(single))]
    assert views == [3 * 8, 3 * 16, 3 * 12]  # the defaults, the page's overrides, the preset (catchment_wide)

    # a sweep over the page's values, then its table
    sweep_dir = root / "sweep"
    proc = _run(python, root, [*sweep, f"hydra.sweep.dir={sweep_dir}"])
    assert proc.returncode == 0, proc.stderr[-2000:]
    jobs = sorted(p for p in sweep_dir.iterdir() if (p / "metrics.json").is_file())
    assert len(jobs) == 2 and all(json.loads((p / "metrics.json").read_text())["status"] == "completed" for p in jobs)
    proc = _run(python, root, [report[0], str(sweep_dir)])
    assert proc.returncode == 0, proc.stderr
    table = (sweep_dir / "summary.md").read_text()
    lines = [line for line in table.splitlines() if line.startswith("| ") and "catchment" in line]
    assert len(lines) == 2 and {"sift", "mfdid"} == {h for line in lines for h in ("sift", "mfdid") if f"| {h} |" in line}
    assert all(col in table for col in ("aae", "success", "n_views")) and "2 runs, 0 failed" in table


@pytest.mark.slow
def test_an_installed_experiments_ranges_are_checked_before_the_run(venv):
    python, root = venv
    run_dir = root / "bad"
    proc = _run(python, root, ["bionav", "experiment=catchment", "experiment.directions=0", f"hydra.run.dir={run_dir}"])
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "experiment.directions=0" in proc.stderr and ">= 1 and <= 360" in proc.stderr
    assert not run_dir.exists()  # refused before Hydra made the run directory
