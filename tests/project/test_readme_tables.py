"""README's table of config groups lists every option Hydra offers, and every entry-point group (issue 32)."""

from __future__ import annotations

import re
from pathlib import Path

from helpers import run_bionav

from bionav.registry import CONFIG_GROUP, GROUPS, SCHEMA_GROUP

README = Path(__file__).resolve().parents[2] / "README.md"


def _help_groups(tmp_path) -> dict[str, list[str]]:
    proc = run_bionav("--help", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    block = proc.stdout.split("== Configuration groups ==")[1].split("== Config ==")[0]
    return {m.group(1): [o.strip() for o in m.group(2).split(",")]
            for m in re.finditer(r"^(\w+): (.+)$", block, flags=re.MULTILINE)}


def _readme_rows() -> dict[str, str]:
    rows = {}
    for line in README.read_text().splitlines():
        m = re.match(r"^\| `(\w+)=` \| (.+) \|$", line)
        if m:
            rows[m.group(1)] = m.group(2)
    return rows


def test_readme_group_table_lists_every_option(tmp_path):
    groups = _help_groups(tmp_path)
    rows = _readme_rows()
    assert {"experiment", "db", "homing", "decoder"} <= set(groups)
    missing = {g: [o for o in opts if f"`{o}`" not in rows.get(g, "")]
               for g, opts in groups.items() if g != "experiment_schema"}
    assert {g: m for g, m in missing.items() if m} == {}
    assert set(rows) <= set(groups)  # no row for a group that does not exist


def test_readme_names_every_entry_point_group():
    text = README.read_text()
    for group in (*GROUPS.values(), CONFIG_GROUP, SCHEMA_GROUP):
        assert f"`{group}`" in text, group


def test_readme_dependencies_are_the_installed_ones():
    """README's "Dependencies and why" names every required dependency of pyproject.toml and no other
    (issue 45: it listed scikit-image, which nothing used); a library it says is not used is not imported."""
    import tomllib

    project = tomllib.loads((README.parent / "pyproject.toml").read_text())["project"]
    required = [re.split(r"[<>=!~ \[]", d, maxsplit=1)[0] for d in project["dependencies"]]
    section = README.read_text().split("### Dependencies and why", 1)[1].split("\n### ", 1)[0]
    named, _, not_used = section.partition("is not used")
    missing = [d for d in required if d.lower() not in named.lower()]
    assert missing == [], f"README does not name {missing}"
    for extra in ("parallel", "slurm", "tune"):
        assert f"bionav[{extra}]" in section and extra in project["optional-dependencies"]
    assert "scikit-image" in named.rsplit(".", 1)[-1] and "scikit-image" not in required  # said: not used
    sources = "\n".join(p.read_text(encoding="utf-8") for p in (README.parent / "bionav").rglob("*.py"))
    assert not re.search(r"^\s*(import skimage|from skimage)", sources, flags=re.MULTILINE)
