"""Import direction: every room imports only the rooms docs/architecture.md allows; one home per concept."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "architecture.md"


def allowed_imports(doc: str) -> dict[str, set[str]]:
    """Room -> rooms it may import, from the "Rooms" table (rooms sharing a row may import each other)."""
    table: dict[str, set[str]] = {}
    header = None
    for line in doc.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")] if line.startswith("|") else None
        if cells is None:
            header = None
            continue
        if cells[:3] == ["room", "holds", "imports"]:
            header = cells
            continue
        if header is None or set(line) <= set("|- "):
            continue
        rooms = {_room_name(n) for n in re.findall(r"`([^`]+)`", cells[0])}
        allowed = {_room_name(n) for n in re.findall(r"`([^`]+)`", cells[2])}
        for room in rooms:
            table[room] = allowed | rooms
    return table


def _room_name(text: str) -> str:
    return text.strip().rstrip("/").removesuffix(".py")


def room_of(module: str) -> str | None:
    """``bionav.light.sun`` -> ``light``; ``bionav.cli`` -> ``cli``; ``bionav`` -> None."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[0] == "bionav" else None


def module_name(path: Path, package_root: Path) -> str:
    parts = list(path.relative_to(package_root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path, module: str) -> list[tuple[int, str]]:
    """Absolute names of the bionav modules a file imports (``from bionav import x`` counts as ``bionav.x``)."""
    out = []
    is_package = path.name == "__init__.py"
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                pkg = module.split(".")
                pkg = pkg if is_package else pkg[:-1]
                pkg = pkg[: len(pkg) - (node.level - 1)]
                base = ".".join(pkg + ([base] if base else []))
            if base == "bionav":
                out += [(node.lineno, f"bionav.{a.name}") for a in node.names]
            else:
                out.append((node.lineno, base))
    return [(line, name) for line, name in out if name == "bionav" or name.startswith("bionav.")]


def violations(package_root: Path, table: dict[str, set[str]], experiments: set[str]) -> list[str]:
    """Imports that run against the table, modules outside it, and experiments importing experiments.

    An experiment is a folder ``bionav/experiments/<name>/`` (``experiments``: the names): its modules
    import no other experiment's folder, and the shared modules of ``experiments/`` (runner,
    settings, merge, ...) import none at all (they find experiments through the registry).
    """
    found = []
    for path in sorted(package_root.rglob("*.py")):
        module = module_name(path, package_root)
        src = room_of(module)
        if src is None:
            continue
        if src not in table:
            found.append(f"{path}: room {src!r} is not in docs/architecture.md")
            continue
        for line, name in imported_modules(path, module):
            dst = room_of(name)
            if dst is None or dst == src or dst == "__version__":
                continue
            if dst not in table[src]:
                found.append(f"{path}:{line}: {src} imports {dst} ({name}), not allowed by docs/architecture.md")
        if src == "experiments":
            found += _experiment_imports(path, module, experiments)
    return found


def _experiment_imports(path: Path, module: str, experiments: set[str]) -> list[str]:
    """An experiment's module importing another experiment, or a shared module importing any experiment."""
    parts = module.split(".")
    own = parts[2] if len(parts) > 2 and parts[2] in experiments else None
    found = []
    for line, name in imported_modules(path, module):
        target = name.split(".")
        if len(target) > 2 and target[1] == "experiments" and target[2] in experiments and target[2] != own:
            who = f"experiment module {module}" if own else f"shared module {module}"
            found.append(f"{path}:{line}: {who} imports the experiment {target[2]}")
    return found


def experiment_names(pyproject: Path) -> set[str]:
    """The experiments bionav registers (its ``bionav.experiments`` entry points)."""
    import tomllib

    return set(tomllib.loads(pyproject.read_text())["project"]["entry-points"]["bionav.experiments"])


def test_no_import_runs_against_the_table():
    table = allowed_imports(DOC.read_text(encoding="utf-8"))
    assert {"errors", "geometry", "light", "homing", "db", "experiments", "cli"} <= set(table)
    found = violations(ROOT / "bionav", table, experiment_names(ROOT / "pyproject.toml"))
    assert found == [], "\n".join(found)


def test_the_check_catches_an_arrow_back_up(tmp_path):
    pkg = tmp_path / "bionav"
    for rel, text in {
        "__init__.py": "",
        "geometry.py": "import numpy\n",
        "light/__init__.py": "from bionav.geometry import x\n",
        "light/sun.py": "from bionav.experiments.cleaning import run\nfrom . import clouds\n",
        "light/clouds.py": "",
        "experiments/__init__.py": "",
        "experiments/cleaning/__init__.py": "",
        "experiments/cleaning/run.py": "from bionav.light import sun\nfrom bionav.experiments.cleaning import plots\n",
        "experiments/cleaning/plots.py": "",
        "experiments/cleaning_replay/__main__.py": "from bionav.experiments.cleaning.run import run\n",
        "experiments/param_sweep/run.py": "def f():\n    from bionav.experiments.grid_homing.run import x\n",
        "experiments/grid_homing/run.py": "from bionav.experiments.common import x\n",
        "experiments/common.py": "",
        "newroom/__init__.py": "",
    }.items():
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text(text)
    table = {"geometry": {"geometry"}, "light": {"geometry", "light"}, "experiments": {"light", "geometry", "experiments"}}
    found = violations(pkg, table, {"cleaning", "param_sweep", "grid_homing"})
    assert len(found) == 4, found
    text = "\n".join(found)
    assert "sun.py:1: light imports experiments" in text
    assert "run.py:2: experiment module bionav.experiments.param_sweep.run imports the experiment grid_homing" in text
    assert "__main__.py:1: shared module bionav.experiments.cleaning_replay.__main__ imports the experiment cleaning" in text
    assert "room 'newroom' is not in" in text


def test_one_folder_per_experiment():
    """Every ``bionav.experiments`` entry point is the class of its own folder, with its config, run and plots."""
    import tomllib

    entries = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["entry-points"]["bionav.experiments"]
    assert {"grid_homing", "cross_db", "param_sweep", "pol_compass", "contrast_lda", "contrast_scan", "skyline_homing",
            "cleaning", "pol_recordings", "route_homing"} <= set(entries)
    for name, target in entries.items():
        assert target.startswith(f"bionav.experiments.{name}:"), target
        folder = ROOT / "bionav" / "experiments" / name
        assert {"__init__.py", "config.py", "run.py", "plots.py"} <= {p.name for p in folder.glob("*.py")}, name
    loose = [p.name for p in (ROOT / "bionav" / "experiments").glob("*.py")
             if p.stem in entries or p.stem.startswith(tuple(f"{n}_" for n in entries))]
    assert loose == [], f"experiment modules outside their folder: {loose}"


def import_graph(package_root: Path) -> dict[str, set[str]]:
    """bionav module -> the bionav modules it imports, at any depth (imports inside functions included).

    ``from bionav.a import b`` names the module ``bionav.a.b`` when there is one, else ``bionav.a``
    (the package, whose ``__init__`` runs); an import of a name that is no module of the package is
    dropped.
    """
    modules = {module_name(p, package_root): p for p in package_root.rglob("*.py")}
    root = package_root.name

    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {}
    for module, path in modules.items():
        out = set()
        is_package = path.name == "__init__.py"
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                out |= {resolve(a.name) for a in node.names if a.name.split(".")[0] == root}
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    pkg = module.split(".") if is_package else module.split(".")[:-1]
                    pkg = pkg[: len(pkg) - (node.level - 1)]
                    base = ".".join(pkg + ([base] if base else []))
                if base.split(".")[0] != root:
                    continue
                out |= {resolve(f"{base}.{a.name}") if f"{base}.{a.name}" in modules else resolve(base)
                        for a in node.names}
        graph[module] = out - {None, module}
    return graph


def import_circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected groups of two or more modules: each is an import circle (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[list[str]] = []

    def visit(v: str) -> None:
        work = [(v, iter(sorted(graph.get(v, ()))))]
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    group.append(w)
                    if w == node:
                        break
                if len(group) > 1:
                    circles.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(circles)


def test_no_import_circle():
    """No two bionav modules import each other, directly or round a circle, imports inside functions included."""
    circles = import_circles(import_graph(ROOT / "bionav"))
    assert circles == [], "import circles: " + "; ".join(" <-> ".join(c) for c in circles)


def test_the_circle_check_finds_a_circle_through_a_function(tmp_path):
    pkg = _package(tmp_path, {
        "__init__.py": "",
        "a.py": "from bionav.b import f\n",
        "b.py": "def f():\n    from bionav import c\n    return c\n",
        "c.py": "import bionav.a\n",
        "d/__init__.py": "from .e import g\n",
        "d/e.py": "def g():\n    from bionav.d import h\n",
        "x.py": "from bionav.a import f\n",  # into the circle, not part of it
    })
    assert import_circles(import_graph(pkg)) == [["bionav.a", "bionav.b", "bionav.c"], ["bionav.d", "bionav.d.e"]]


def test_one_definition_per_concept():
    """The issue's grep: each of these is defined at most once in bionav/."""
    pattern = re.compile(r"^\s*(def (sun_position|resize_panorama|butterworth_lowpass|sift_features|edge_filter|"
                         r"parse_time|cache_key|default_cache_dir|write_atomic|write_json_atomic|"
                         r"direction_from_angles|compass_to_azimuth|wrap_axial|evaluate_agents|neighbour_table)\b"
                         r"|class (CloudField|SiftFeatures|SunPosition)\b)", re.M)
    seen: dict[str, list[str]] = {}
    for path in (ROOT / "bionav").rglob("*.py"):
        for m in pattern.finditer(path.read_text(encoding="utf-8")):
            seen.setdefault(m.group(1).split("(")[0].strip(), []).append(str(path.relative_to(ROOT)))
    twice = {k: v for k, v in seen.items() if len(v) > 1}
    assert twice == {}, twice
    assert "def sun_position" in seen and "def butterworth_lowpass" in seen  # the pattern does match


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    """A throw-away ``bionav`` package under ``tmp_path`` with these files (path relative to it -> text)."""
    pkg = tmp_path / "bionav"
    for rel, text in files.items():
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text(text)
    return pkg


def console_writes(path: Path) -> list[int]:
    """Lines of ``print(...)`` calls and ``sys.stdout``/``sys.stderr`` uses in one file."""
    lines = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "print":
            lines.append(node.lineno)
        elif (isinstance(node, ast.Attribute) and node.attr in {"stdout", "stderr"}
              and isinstance(node.value, ast.Name) and node.value.id == "sys"):
            lines.append(node.lineno)
    return sorted(set(lines))


def rooms_that_print(package_root: Path, table: dict[str, set[str]]) -> list[str]:
    """Modules that write to the console although their room has no command line.

    A room has a command line when the table lets it import ``cli_main`` (the
    wrapper of every ``__main__``); ``cli_main`` itself is where the messages
    are printed.
    """
    found = []
    for path in sorted(package_root.rglob("*.py")):
        room = room_of(module_name(path, package_root))
        if room is None or room == "cli_main" or "cli_main" in table.get(room, set()):
            continue
        found += [f"{path}:{line}: room {room} writes to the console" for line in console_writes(path)]
    return found


def test_only_rooms_with_a_command_line_print():
    """``errors`` and the other rooms without a ``__main__`` never print: the command line does."""
    table = allowed_imports(DOC.read_text(encoding="utf-8"))
    assert "cli_main" in table and table["cli_main"] == {"errors", "cli_main"}
    assert "cli_main" not in table["errors"] and "cli_main" in table["logs"]
    found = rooms_that_print(ROOT / "bionav", table)
    assert found == [], "\n".join(found)


def test_the_print_check_catches_a_print_in_a_low_room(tmp_path):
    pkg = _package(tmp_path, {
        "__init__.py": "",
        "errors.py": "import sys\n\ndef f():\n    print('x', file=sys.stderr)\n",
        "geometry.py": "def f(x):\n    return x  # print(x) in a comment is fine\n",
        "cli_main.py": "print('fine here')\n",
        "logs/__main__.py": "print('fine here too')\n",
    })
    table = {"errors": {"errors"}, "geometry": {"geometry"}, "cli_main": {"errors", "cli_main"},
             "logs": {"errors", "cli_main", "logs"}}
    assert rooms_that_print(pkg, table) == [f"{pkg / 'errors.py'}:4: room errors writes to the console"]


def concept_table(doc: str) -> list[tuple[str, list[str], list[str], str]]:
    """``(concept, names, home modules, notes)`` per row of the "concept | names | home | notes" table."""
    rows, inside = [], False
    for line in doc.splitlines():
        if not line.startswith("|"):
            inside = False
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[:4] == ["concept", "names", "home", "notes"]:
            inside = True
            continue
        if not inside or set(line) <= set("|- "):
            continue
        rows.append((cells[0], re.findall(r"`([^`]+)`", cells[1]), re.findall(r"`([^`]+)`", cells[2]), cells[3]))
    return rows


def module_definitions(package_root: Path) -> dict[str, list[str]]:
    """Name -> the modules (paths relative to the package) that define it at module level (def or class)."""
    found: dict[str, list[str]] = {}
    for path in sorted(package_root.rglob("*.py")):
        rel = path.relative_to(package_root).as_posix()
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                found.setdefault(node.name, []).append(rel)
    return found


def concept_violations(rows, definitions: dict[str, list[str]]) -> list[str]:
    """Names defined outside their row's homes, names their homes do not define, second homes without a note."""
    problems = []
    for concept, names, homes, notes in rows:
        if len(homes) > 1 and not notes:
            problems.append(f"{concept}: {len(homes)} homes ({', '.join(homes)}) and no note saying why")
        for name in names:
            where = definitions.get(name, [])
            if not set(where) & set(homes):
                problems.append(f"{concept}: {name} is not defined in {', '.join(homes) or 'any home'}"
                                f"{' (defined in ' + ', '.join(where) + ')' if where else ''}")
            for module in where:
                if module not in homes:
                    problems.append(f"{concept}: {name} is defined a second time, in {module} "
                                    f"(its home: {', '.join(homes)})")
    return problems


def test_every_concept_has_its_homes_and_no_other():
    rows = concept_table(DOC.read_text(encoding="utf-8"))
    names = [n for _, ns, _, _ in rows for n in ns]
    assert len(rows) >= 30 and {"sun_position", "sift_features", "evectors_from_counts", "RunLock", "read_json_file",
                                "bounded", "CloudLayer", "CaptureLight", "Material", "run_main"} <= set(names)
    assert len(names) == len(set(names)), "a name listed in two rows"
    found = concept_violations(rows, module_definitions(ROOT / "bionav"))
    assert found == [], "\n".join(found)


def test_the_concept_check_catches_a_second_definition(tmp_path):
    doc = ("| concept | names | home | notes |\n|---|---|---|---|\n"
           "| sun position | `sun_position`, `SunPosition` | `light/sun.py` | |\n"
           "| materials | `Material` | `light/materials.py`, `world/scene.py` | |\n"
           "| clouds | `CloudLayer` | `light/clouds.py` | |\n")
    pkg = _package(tmp_path, {
        "light/sun.py": "class SunPosition:\n    pass\n\n\ndef sun_position(when):\n    return when\n",
        "world/scene.py": "class Material:\n    pass\n",
        "light/materials.py": "class Material:\n    pass\n",
        "spectral/sky.py": "def sun_position(when):  # a second copy\n    return when\n\n\n"
                           "def helper():\n    def CloudLayer():  # nested: not a module-level definition\n"
                           "        pass\n",
    })
    rows = concept_table(doc)
    assert [r[0] for r in rows] == ["sun position", "materials", "clouds"]
    found = concept_violations(rows, module_definitions(pkg))
    assert found == ["sun position: sun_position is defined a second time, in spectral/sky.py (its home: light/sun.py)",
                     "materials: 2 homes (light/materials.py, world/scene.py) and no note saying why",
                     "clouds: CloudLayer is not defined in light/clouds.py"]


#: names that are a protocol several modules implement, not one concept: an experiment's or tool's
#: ``run``, a ``__main__``'s ``main``, a split experiment's ``merge`` and an entry point's ``register``
PROTOCOL_NAMES = {"run", "main", "merge", "register"}


def public_definitions(package_root: Path) -> dict[str, list[str]]:
    """Public module-level ``def``/``class`` name -> the modules of ``package_root`` that define it."""
    found: dict[str, list[str]] = {}
    for path in sorted(package_root.rglob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and not node.name.startswith("_"):
                found.setdefault(node.name, []).append(str(path.relative_to(package_root.parent)))
    return found


def names_defined_twice(package_root: Path) -> dict[str, list[str]]:
    return {name: homes for name, homes in public_definitions(package_root).items()
            if len(homes) > 1 and name not in PROTOCOL_NAMES}


def test_each_public_name_means_one_thing():
    twice = names_defined_twice(ROOT / "bionav")
    assert not twice, "public names defined in more than one module (rename one, or fold them): " + "; ".join(
        f"{name}: {', '.join(homes)}" for name, homes in sorted(twice.items()))


def test_a_public_name_defined_twice_is_found(tmp_path):
    package = tmp_path / "pkg"
    (package / "a").mkdir(parents=True)
    (package / "a" / "x.py").write_text("def solve():\n    pass\n\ndef run():\n    pass\n")
    (package / "y.py").write_text("class Solve:\n    pass\n\ndef solve():\n    pass\n\n"
                                  "def run():\n    pass\n\ndef _private():\n    pass\n")
    (package / "z.py").write_text("def _private():\n    pass\n")
    assert names_defined_twice(package) == {"solve": ["pkg/a/x.py", "pkg/y.py"]}


MAX_MODULE_LINES = 600
MAX_FUNCTION_CODE_LINES = 80


def code_lines(source: str, node: ast.AST) -> int:
    """Lines of a function that hold code: not blank, not only a comment, not its docstring."""
    import io
    import tokenize

    body = getattr(node, "body", [])
    doc = None
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        doc = range(body[0].lineno, body[0].end_lineno + 1)
    text = "\n".join(source.splitlines()[node.lineno - 1:node.end_lineno]) + "\n"
    skip = (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER)
    lines = set()
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type in skip:
            continue
        lines.update(n + node.lineno - 1 for n in range(tok.start[0], tok.end[0] + 1))
    return len([n for n in lines if doc is None or n not in doc])


def oversized(package_root: Path) -> list[str]:
    """Modules over :data:`MAX_MODULE_LINES` lines and functions over :data:`MAX_FUNCTION_CODE_LINES` lines of code."""
    found = []
    for path in sorted(package_root.rglob("*.py")):
        source = path.read_text(encoding="utf-8")
        where = path.relative_to(package_root.parent)
        if len(source.splitlines()) > MAX_MODULE_LINES:
            found.append(f"{where}: {len(source.splitlines())} lines")
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = code_lines(source, node)
                if n > MAX_FUNCTION_CODE_LINES:
                    found.append(f"{where}:{node.lineno} {node.name}: {n} lines of code")
    return found


def test_modules_and_functions_stay_small():
    assert oversized(ROOT / "bionav") == []


def test_an_oversized_function_is_found(tmp_path):
    package = tmp_path / "pkg"
    package.mkdir()
    long_body = "".join(f"    x{i} = {i}  # a comment\n\n" for i in range(81))
    (package / "a.py").write_text(f'def f():\n    """Doc\n\n    string."""\n{long_body}    return 0\n')
    (package / "b.py").write_text('def g():\n    """Doc."""\n' + "    # only comments\n" * 200 + "    return 0\n")
    assert oversized(package) == ["pkg/a.py:1 f: 83 lines of code"]  # def + 81 assignments + return
