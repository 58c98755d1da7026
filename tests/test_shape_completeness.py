"""Every kind of object the scene format accepts is whole everywhere: the renderer sees it
(its kernel and its bounds), CSG cuts it (its crossings) when it bounds a volume, its texture
coordinates are documented, POV-Ray export writes it, the editor adds it from the Add menu
and its Shape section edits every parameter, ``whitted info`` lists it, and
docs/scene-format.md has its row. A kind that misses one of these fails here by name."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from whitted import scene as S
from whitted.export.pov import scene_to_pov
from whitted.gui import catalog
from whitted.gui.fields import NOT_SHAPE_FIELDS, object_specs
from whitted.kernels.shapes import PIECES

ROOT = Path(__file__).resolve().parents[1]
KINDS = catalog.shape_kinds()

#: parameters a Shape section does not edit, each with where they are edited instead
EDITED_ELSEWHERE = {
    "csg": {"objects": "the scene tree (children are objects of their own)"},
    "mesh": {name: "a model's own arrays: edited in a modeller, not number by number"
             for name in ("vertices", "faces", "normals", "uvs")},
}
#: the other form of shapes given in one of two (a box: min/max or corner/edges; a mesh: a
#: file or arrays)
OTHER_FORM = {"box": S.Box(corner=(0, 0, 0), edges=((1, 0, 0), (0, 1, 0), (0, 0, 1))),
              "mesh": S.Mesh(file="model.obj")}


def sample(kind: str):
    """One object of each kind near the origin: the editor's ready-made one, or for a mesh
    (added from a model file) a closed tetrahedron given inline."""
    if kind == "mesh":
        return S.Mesh(vertices=[(-0.5, 0, -0.5), (0.5, 0, -0.5), (0, 0, 0.5), (0, 0.8, 0)],
                      faces=[(0, 2, 1), (0, 1, 3), (1, 2, 3), (2, 0, 3)])
    return catalog._objects(np.zeros(3))[kind]()


def lone_scene(obj) -> S.Scene:
    """``obj`` alone, seen from above and in front, in a tiny picture."""
    return S.Scene(camera=S.Camera(position=(0.0, 2.0, 3.0), look_at=(0.0, 0.2, 0.0), fov=50),
                   objects=[obj], lights=[S.PointLight(position=(2.0, 4.0, 3.0))],
                   render=S.RenderSettings(width=16, height=12, threads=1))


def test_the_kinds_are_the_scene_formats():
    assert {"sphere", "torus", "mesh", "csg"} <= set(KINDS)
    assert len(KINDS) == len(set(KINDS))


@pytest.mark.parametrize("kind", KINDS)
def test_the_editor_adds_it_and_edits_every_parameter(kind):
    missing = []
    scene = lone_scene(sample("sphere"))
    if kind in catalog.OBJECT_KINDS:
        try:
            made = catalog.new_object(scene, kind)
        except KeyError:
            made = None
        if made is None or made.type != kind:
            missing.append("a ready-made object for the Add Object menu (gui/catalog.py)")
    elif kind not in catalog.ADDED_OTHERWISE:
        missing.append("an entry in the editor's Add menu (gui/catalog.py)")
    edited = {spec.path[0] for obj in (sample(kind), OTHER_FORM.get(kind)) if obj is not None
              for spec in object_specs(obj)}
    parameters = set(type(sample(kind)).model_fields) - set(NOT_SHAPE_FIELDS)
    for name in sorted(parameters - edited - set(EDITED_ELSEWHERE.get(kind, {}))):
        missing.append(f"the editor's Shape section edits no {name!r} (gui/fields.py)")
    assert not missing, f"{kind}: " + "; ".join(missing)


@pytest.mark.parametrize("kind", KINDS)
def test_pov_export_info_and_docs_name_it(kind, tmp_path):
    from cli_run import run_main

    obj = sample(kind)
    scene = lone_scene(obj)
    missing = []
    try:
        text = scene_to_pov(scene)
    except Exception as exc:  # noqa: BLE001 - any failure is what is missing
        text = ""
        missing.append(f"POV-Ray export ({exc})")
    else:
        if not re.search(r"^\s*(sphere|plane|mesh2?|disc|box|cylinder|cone|torus|union|"
                         r"intersection|difference|merge)\s*\{", text, re.M):
            missing.append("POV-Ray export writes no object")
    path = tmp_path / "one.toml"
    scene.save(path)
    status, out, err = run_main("info", path, cwd=tmp_path)
    if status != 0 or not re.search(rf"^\s*\[0\] {kind}\b", out, re.M):
        missing.append(f"a `whitted info` line ({err.strip() or 'not listed'})")
    for what, cells in zip(("shape", "texture-coordinate"), shape_tables(), strict=True):
        if not any(f"`{kind}`" in cell for cell in cells):
            missing.append(f"a row in docs/scene-format.md's {what} table")
    assert not missing, f"{kind}: " + "; ".join(missing)


def shape_tables() -> list[list[str]]:
    """The first cells of docs/scene-format.md's tables of shapes (the ones with a `sphere`
    row): the shapes' parameters, then their texture coordinates."""
    doc = (ROOT / "docs" / "scene-format.md").read_text(encoding="utf-8")
    tables = re.findall(r"(?:^\|.*\n)+", doc, re.M)
    found = [[row.split("|")[1] for row in t.splitlines()] for t in tables]
    found = [cells for cells in found if any(c.strip() == "`sphere`" for c in cells)]
    assert len(found) == 2, "docs/scene-format.md: the shape and texture-coordinate tables"
    return found


def _bounds_hold(kind: str, obj) -> list[str]:
    """The compiled box of a bounded shape is finite and inside the editor's (looser) box of
    it; that the renderer then sees the shape says the box is not too small for the rays."""
    from whitted.compile.scene import compile_scene
    from whitted.gui.transform_tool import item_bounds

    compiled = compile_scene(lone_scene(obj))
    if kind == "plane":
        return [] if len(compiled.geometry.unbounded) == 1 else ["an unbounded plane row"]
    lo, hi = compiled.bounds_min, compiled.bounds_max
    box = item_bounds(obj, None)
    if not (np.all(np.isfinite(lo)) and np.all(lo <= hi)):
        return [f"bounds (compiled {lo}..{hi})"]
    if box is None or not (np.all(box[0] - 1e-6 <= lo) and np.all(hi <= box[1] + 1e-6)):
        return [f"bounds (compiled {lo}..{hi}, outside the shape's box {box})"]
    return []


def _seen(obj) -> bool:
    from whitted.render.api import render_aovs

    return bool(np.any(render_aovs(lone_scene(obj))["id"] == 0))


@pytest.mark.parametrize("kind", KINDS)
def test_the_renderer_sees_it_alone_and_in_csg(kind):
    obj = sample(kind)
    missing = _bounds_hold(kind, obj)
    if not _seen(obj):
        missing.append("a kernel that hits it (no pixel shows it)")
    try:
        cut = S.CSG(operation="intersection",
                    objects=[obj, S.Box(min=(-3.0, -3.0, -3.0), max=(3.0, 3.0, 3.0))])
    except ValueError as exc:  # bounds no volume: CSG refuses it, and says why
        if "cannot take part in CSG" not in str(exc):
            missing.append(f"CSG refuses it without saying why ({exc})")
    else:
        if not _seen(cut):
            missing.append("CSG crossings (no pixel shows it inside a CSG intersection)")
    assert not missing, f"{kind}: " + "; ".join(missing)


def _refused_by_csg(obj) -> bool:
    try:
        S.CSG(operation="union", objects=[obj])
    except ValueError as exc:
        assert "cannot take part in CSG" in str(exc)
        return True
    return False


#: the kinds whose objects are walked by code of their own rather than asked for through
#: kernels/shapes/dispatch.py, and what walks them
COMPOSITES = {
    "mesh": "kernels/mesh.py walks an instance's BVH; a small mesh is flattened to triangles",
    "csg": "kernels/csg.py walks the object's leaves, each asked through dispatch.py",
}
KERNEL_PIECES = ("hit", "crossings", "normal", "uv")


def dispatched_names() -> set[str]:
    """The functions kernels/shapes/dispatch.py calls: what the integrator can reach."""
    import ast

    tree = ast.parse((ROOT / "src" / "whitted" / "kernels" / "shapes" / "dispatch.py")
                     .read_text(encoding="utf-8"))
    return {node.func.id for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)}


def piece_problems(kind: str, pieces: dict | None, dispatched: set[str]) -> list[str]:
    """What ``kind`` lacks of the pieces kernels/shapes/__init__.py asks of every shape:
    each piece named and existing; for an analytic shape, its kernel pieces in one file of
    its own under kernels/shapes/, each asked for in kernels/shapes/dispatch.py, and its
    rows the function compile/shapes.py's ``ROWS`` gives its scene class."""
    import importlib

    from whitted.compile.shapes import ROWS

    if pieces is None:
        return ["no entry in kernels/shapes/__init__.py PIECES"]
    missing = [f"{p} (none named)" for p in ("rows", *KERNEL_PIECES) if p not in pieces]
    modules = set()
    for piece, where in pieces.items():
        if where is None:
            if piece != "crossings" or not _refused_by_csg(sample(kind)):
                missing.append(f"{piece} (none named)")
            continue
        module, _, name = where.partition(":")
        if not hasattr(importlib.import_module(f"whitted.{module}"), name):
            missing.append(f"{piece} ({where} does not exist)")
            continue
        if kind in COMPOSITES:
            continue
        if piece == "rows":
            rows = ROWS.get(type(sample(kind)))
            if rows is None or f"compile.shapes:{rows.__name__}" != where:
                missing.append(f"rows ({where} is not compile/shapes.py ROWS's entry for "
                               f"{type(sample(kind)).__name__})")
            continue
        modules.add(module)
        if name not in dispatched:
            missing.append(f"{piece} ({name} is not asked for in kernels/shapes/dispatch.py)")
    if len(modules) > 1 or any(not m.startswith("kernels.shapes.") for m in modules):
        missing.append(f"its kernel pieces in one file under kernels/shapes/ (they are in "
                       f"{', '.join(sorted(modules))})")
    if pieces.get("crossings") is not None and kind != "csg" and _refused_by_csg(sample(kind)):
        missing.append("crossings named for a kind CSG refuses")
    return missing


@pytest.mark.parametrize("kind", KINDS)
def test_its_pieces_are_in_its_file_and_dispatched(kind):
    """kernels/shapes/ names the function of each piece of every kind (one named hop), the
    analytic kinds' all in the kind's own file and reached through dispatch.py."""
    missing = piece_problems(kind, PIECES.get(kind), dispatched_names())
    assert not missing, f"{kind}: " + "; ".join(missing)


def test_the_piece_check_names_what_is_missing():
    """A torus whose uv is not named, whose normal lives elsewhere and is not dispatched, and
    whose rows are not compile/shapes.py's: each named."""
    broken = dict(PIECES["torus"])
    del broken["uv"]
    broken["normal"] = "kernels.shapes.box:box_local"
    broken["rows"] = "compile.shapes:sphere_rows"
    assert piece_problems("torus", broken, dispatched_names()) == [
        "uv (none named)",
        "rows (compile.shapes:sphere_rows is not compile/shapes.py ROWS's entry for Torus)",
        "normal (box_local is not asked for in kernels/shapes/dispatch.py)",
        "its kernel pieces in one file under kernels/shapes/ (they are in "
        "kernels.shapes.box, kernels.shapes.torus)",
    ]
    assert piece_problems("torus", None, set()) == [
        "no entry in kernels/shapes/__init__.py PIECES"]
    assert piece_problems("torus", PIECES["torus"], dispatched_names() - {"torus_uv"}) == [
        "uv (torus_uv is not asked for in kernels/shapes/dispatch.py)"]


def test_every_analytic_scene_shape_has_rows_and_a_dispatch():
    """compile/shapes.py ``ROWS`` covers every analytic scene class, and dispatch.py asks for
    a hit, a normal and a uv of every shape code the rows write."""
    import ast
    import inspect

    from whitted.compile import shapes as compile_shapes

    analytic = {type(sample(k)) for k in KINDS if k not in COMPOSITES}
    assert set(compile_shapes.ROWS) == analytic
    written = {node.id for fn in set(compile_shapes.ROWS.values())
               for node in ast.walk(ast.parse(inspect.getsource(fn)))
               if isinstance(node, ast.Name) and node.id.startswith("SHAPE_")}
    assert len(written) == len(analytic) - 1  # the cylinder and the cone: frustum rows
    for core, extra in (("intersect_local", "extra_shape_t"),
                        ("normal_local", "extra_shape_normal"), ("uv_local", "extra_shape_uv")):
        asked = dispatch_body(core) + dispatch_body(extra)
        if core == "normal_local":  # the box's and the frustum's behind a call
            asked += dispatch_body("_solid_normal")
        assert not {c for c in written if c not in asked}, f"{core} misses a shape code"


def dispatch_body(name: str) -> str:
    """The source of function ``name`` of kernels/shapes/dispatch.py."""
    source = (ROOT / "src" / "whitted" / "kernels" / "shapes" / "dispatch.py").read_text(
        encoding="utf-8")
    body = source[source.index(f"def {name}("):]
    return body[: body.index("\n@kernel")] if "\n@kernel" in body else body


def test_the_kernel_cache_key_covers_the_shapes_package(tmp_path):
    """A change to a shape's file (in kernels/shapes/) compiles the kernels again."""
    import shutil

    from whitted.jit import cache

    root = Path(cache.__file__).parents[1]
    copy = tmp_path / "whitted"
    for folder in (*cache.KERNEL_DIRS, "jit"):
        shutil.copytree(root / folder, copy / folder,
                        ignore=shutil.ignore_patterns("__pycache__"))
    before = cache.kernel_source_hash(copy)
    assert before == cache.kernel_source_hash(root)
    torus = copy / "kernels" / "shapes" / "torus.py"
    torus.write_text(torus.read_text() + "\n# changed\n")
    assert cache.kernel_source_hash(copy) != before


#: the names of shape codes a kernel outside kernels/shapes/ may not compare a row's type with
SHAPE_CODE = re.compile(r"^(SHAPE_\w+|FIRST_EXTRA_SHAPE)$")


def kind_comparisons(source: str, where: str) -> list[str]:
    """``where:line`` of every comparison in ``source`` with a ``SHAPE_*`` code (or
    ``FIRST_EXTRA_SHAPE``) as an operand, however it is spelt (``layout.SHAPE_CSG`` too)."""
    import ast

    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Compare):
            continue
        for operand in (node.left, *node.comparators):
            name = (operand.id if isinstance(operand, ast.Name)
                    else operand.attr if isinstance(operand, ast.Attribute) else "")
            if SHAPE_CODE.match(name):
                found.append((node.lineno, f"{where}:{node.lineno} compares with {name}"))
                break
    return [text for _, text in sorted(found)]


def test_kernels_ask_dispatch_to_tell_kinds_apart():
    """No kernel module outside kernels/shapes/ compares a row's type with a shape code: each
    such decision is a named predicate of kernels/shapes/dispatch.py."""
    kernels = ROOT / "src" / "whitted" / "kernels"
    found = []
    for path in sorted(kernels.rglob("*.py")):
        if kernels / "shapes" in path.parents:
            continue
        found += kind_comparisons(path.read_text(encoding="utf-8"),
                                  str(path.relative_to(ROOT)))
    assert not found, "ask kernels/shapes/dispatch.py instead: " + "; ".join(found)


def test_the_kind_comparison_check_names_file_and_line():
    source = ("x = SHAPE_CSG\n"
              "if geo.prim_info[i, PRIM_TYPE] == SHAPE_TRIANGLE and smooth:\n"
              "    pass\n"
              "ok = typ >= layout.FIRST_EXTRA_SHAPE\n"
              "mesh = is_extra(typ) or layout.SHAPE_MESH != typ\n")
    assert kind_comparisons(source, "kernels/x.py") == [
        "kernels/x.py:2 compares with SHAPE_TRIANGLE",
        "kernels/x.py:4 compares with FIRST_EXTRA_SHAPE",
        "kernels/x.py:5 compares with SHAPE_MESH",
    ]
