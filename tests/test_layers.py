"""The architecture's layers, checked on the source: every import (at module level or inside a
function) goes from a package to one on a lower layer, none reaches up to the top package
``whitted`` itself, and no modules import each other in a circle. The layer order is written
once, in docs/architecture.md (the ``layers`` block), and the same file maps every source file
under its package, in that order."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "whitted"


def layers() -> list[list[str]]:
    """The packages of each layer, bottom first, read from docs/architecture.md."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    block = re.search(r"```layers\n(.*?)```", text, re.S)
    assert block, "docs/architecture.md has no ```layers block"
    rows = [line.split("#")[0].split() for line in block.group(1).splitlines()]
    return [row for row in rows if row][::-1]  # written top first


def module_name(path: Path, src: Path = SRC) -> str:
    parts = list(path.relative_to(src.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _type_checking_lines(tree: ast.Module) -> set[int]:
    """Lines inside ``if TYPE_CHECKING:`` blocks (imports for type checkers only)."""
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                lines.update(range(child.lineno, (child.end_lineno or child.lineno) + 1))
    return lines


def imports(src: Path = SRC) -> dict[str, set[tuple[str, int]]]:
    """module -> {(imported whitted module, line)} for every module of the package."""
    modules = {module_name(p, src): p for p in src.rglob("*.py")}
    found: dict[str, set[tuple[str, int]]] = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        skip = _type_checking_lines(tree)
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        targets: set[tuple[str, int]] = set()
        for node in ast.walk(tree):
            if getattr(node, "lineno", None) in skip:
                continue
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base_name = ".".join(base + ([node.module] if node.module else []))
                else:
                    base_name = node.module or ""
                for alias in node.names:
                    full = f"{base_name}.{alias.name}"
                    targets.add((full if full in modules else base_name, node.lineno))
            elif isinstance(node, ast.Import):
                targets.update((a.name, node.lineno) for a in node.names)
        found[name] = {(t, line) for t, line in targets
                       if t.split(".")[0] == "whitted" and t in modules}
    return found


def package_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_every_package_has_a_layer():
    placed = {p for row in layers() for p in row}
    packages = {package_of(m) for m in imports()} - {"", "__main__"}
    assert packages <= placed, f"not in the layers block: {sorted(packages - placed)}"


def upward_imports(found: dict[str, set[tuple[str, int]]],
                   order: list[list[str]]) -> list[str]:
    """``module:line imports target`` for each import that does not go down a layer (the top
    package ``whitted``, its lazy public API, is above every layer)."""
    level = {p: i for i, row in enumerate(order) for p in row}
    wrong = []
    for module, targets in found.items():
        here = package_of(module)
        if here in ("", "__main__"):  # the lazy public API and `python -m whitted`: the top
            continue
        for target, line in targets:
            if target == "whitted":
                wrong.append(f"{module}:{line} imports the top package whitted")
                continue
            there = package_of(target)
            if there and there != here and level[there] >= level[here]:
                wrong.append(f"{module}:{line} imports {target}")
    return sorted(wrong)


def test_imports_go_down_the_layers():
    wrong = upward_imports(imports(), layers())
    assert not wrong, "imports that do not go down a layer:\n" + "\n".join(wrong)


def module_circles(found: dict[str, set[tuple[str, int]]]) -> list[list[str]]:
    # importing a module runs its packages' __init__ first: not an import of one's own
    graph = {m: {t for t, _ in ts if t != m and not m.startswith(t + ".")}
             for m, ts in found.items()}
    # a package's __init__ importing its own modules is how packages work, not a circle
    for m in graph:
        graph[m] = {t for t in graph[m] if not t.startswith(m + ".")}
    return _strongly_connected(graph)


def test_no_module_circles():
    circles = module_circles(imports())
    assert not circles, "modules that import each other in a circle:\n" + "\n".join(
        " -> ".join(sorted(c)) for c in circles)


def _strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(component)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_checks_catch_an_upward_import_and_a_circle(tmp_path):
    """The checker itself, on a made-up package: scene importing render (upward), errors
    importing scene (upward from the bottom), marks importing the top package, two render
    modules importing each other."""
    src = tmp_path / "whitted"
    files = {
        "__init__.py": "",
        "errors.py": "def f():\n    from .scene import model\n",
        "marks.py": "from whitted import load_scene\n",
        "scene/__init__.py": "",
        "scene/model.py": "from ..render.api import go\nfrom ..errors import E\n",
        "render/__init__.py": "",
        "render/api.py": "from ..scene import model\nfrom . import jobs\n",
        "render/jobs.py": "from .api import go\n",
    }
    for name, text in files.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_text(text)
    found = imports(src)
    order = [["errors", "marks"], ["scene"], ["render"]]
    assert upward_imports(found, order) == [
        "whitted.errors:2 imports whitted.scene.model",
        "whitted.marks:1 imports the top package whitted",
        "whitted.scene.model:1 imports whitted.render.api",
    ]
    assert [sorted(c) for c in module_circles(found)] == [
        ["whitted.errors", "whitted.render.api", "whitted.render.jobs", "whitted.scene.model"],
    ]


MAP_HEADING = "## Every file, layer by layer"
TOP = "the package"


def file_map(text: str) -> list[tuple[str, list[tuple[str, str]]]]:
    """(package, [(file, what it holds)]) in the order docs/architecture.md lists them."""
    start = text.index(MAP_HEADING) + len(MAP_HEADING)
    end = text.find("\n## ", start)
    sections: list[tuple[str, list[tuple[str, str]]]] = []
    for line in text[start:end if end >= 0 else None].splitlines():
        if line.startswith("### "):
            sections.append((line[4:].strip(), []))
        elif line.startswith("- `"):
            path, _, what = line[3:].partition("`")
            sections[-1][1].append((path, what.removeprefix(":").strip()))
    return sections


def map_problems(text: str, src: Path, order: list[list[str]]) -> list[str]:
    """What the map gets wrong: files missing or listed twice or not there, files under the
    wrong package, packages out of the layers' order, lines that say nothing."""
    sections = file_map(text)
    files = {p.relative_to(src).as_posix() for p in src.rglob("*.py")}
    packages_top_first = [TOP] + [p for row in order[::-1] for p in row]
    problems = []
    listed: list[str] = []
    for package, rows in sections:
        for path, what in rows:
            listed.append(path)
            owner = TOP if "/" not in path and path in ("__init__.py", "__main__.py") \
                else path.split("/")[0].removesuffix(".py")
            if owner != package:
                problems.append(f"{path} is listed under {package}, not {owner}")
            if not what:
                problems.append(f"{path}: no line on what it holds")
    problems += [f"{p} is not in the map" for p in sorted(files - set(listed))]
    problems += [f"{p} is in the map but not in src/whitted" for p in sorted(set(listed) - files)]
    problems += [f"{p} is listed twice" for p in sorted({p for p in listed if listed.count(p) > 1})]
    named = [package for package, _ in sections]
    unknown = [p for p in named if p not in packages_top_first]
    problems += [f"section {p!r} is no package of the layers block" for p in unknown]
    known = [p for p in named if p in packages_top_first]
    if known != sorted(known, key=packages_top_first.index):
        problems.append("the packages are not in the layers block's order: " + ", ".join(known))
    return problems


def test_the_map_lists_every_file_under_its_layer():
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    problems = map_problems(text, SRC, layers())
    assert not problems, "docs/architecture.md:\n" + "\n".join(problems)


def test_the_concept_table_names_files_that_exist():
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = text[text.index("## Where each concept lives"):]
    table = table[: table.index("\n## ")]
    named, missing = 0, set()
    for row in (r for r in table.splitlines() if r.startswith("| ")):
        cell = row.rsplit("|", 2)[-2]
        folders = [""] + [f + "/" for f in re.findall(r"`(\w+)/`", cell)]  # `farm/` (`still.py`)
        for name in re.findall(r"`([\w/]+\.py)`", cell):
            named += 1
            if not any((SRC / (folder + name)).is_file() for folder in folders):
                missing.add(name)
    assert named and not missing, f"the concept table names missing files: {missing}"


def test_the_map_check_finds_a_missing_a_misplaced_and_a_disordered_file(tmp_path):
    src = tmp_path / "whitted"
    for name in ("__init__.py", "errors.py", "scene/__init__.py", "scene/shapes.py",
                 "render/api.py"):
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_text("")
    order = [["errors"], ["scene"], ["render"]]
    text = (f"{MAP_HEADING}\n\n### the package\n\n- `__init__.py`: the API\n\n"
            "### errors\n\n- `errors.py`:\n\n"
            "### scene\n\n- `scene/__init__.py`: scenes\n- `render/api.py`: jobs\n\n## Next\n")
    assert map_problems(text, src, order) == [
        "errors.py: no line on what it holds",
        "render/api.py is listed under scene, not render",
        "scene/shapes.py is not in the map",
        "the packages are not in the layers block's order: the package, errors, scene",
    ]
