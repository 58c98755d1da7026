"""Property-based fuzzing (hypothesis) of what users type (issue 13): mutated example scenes
(values, types, deleted and duplicated keys, nesting), random bytes and truncations of OBJ/MTL
files, and random command options. Every case ends in success, or in exit status 2 with one
``error:`` line: never a traceback, an internal error, a hang or a crash.

The command runs in-process through its console entry point (see test_reliability.run_main),
so a few hundred cases take seconds; the example counts are bounded for CI."""

from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from test_reliability import SCENE, run_main
from whitted.assets import load_mesh
from whitted.errors import SceneError

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
def fuzz(examples: int) -> settings:
    """Bounded and repeatable: the same cases on every run, no example database."""
    return settings(max_examples=examples, deadline=None, database=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.function_scoped_fixture])


def assert_clean(result: tuple[int, str, str]) -> None:
    """Success, or status 2 with exactly one ``error:`` line; never a traceback."""
    code, out, err = result
    assert "Traceback" not in out + err, err
    assert "internal error" not in err, err
    assert "Warning" not in err, err  # no raw numpy or Pillow warnings
    if code == 0:
        return
    assert code == 2, (code, out, err)
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), err


# ------------------------------------------------------------------------------- scene files

SCENES = {path.name: tomllib.loads(path.read_text()) for path in sorted(EXAMPLES.glob("*.toml"))
          if path.name not in ("teapot_glass.toml", "textured.toml")}  # no big models: fast
SCENES["small.toml"] = tomllib.loads(SCENE)

scalars = st.one_of(
    st.integers(-3, 3), st.integers(-(2**70), 2**70), st.floats(allow_nan=True),
    st.sampled_from([0.0, -1.0, 1e-300, 1e300, 1e16, 0.5, 2.0]),
    st.booleans(), st.text(max_size=12),
    st.sampled_from(["#ff0000", "#zzzzzz", "[/bold]", ":100:", "glass", "sphere", "", "x" * 300]),
)
values = st.recursive(scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=3)),
    max_leaves=8)


def _paths(data, prefix=()):
    """Every (path, value) in nested dicts and lists."""
    yield prefix, data
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _paths(v, (*prefix, i))


def _mutate(data, path, how: str, value):
    if not path:
        return data
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    key = path[-1]
    if how == "replace":
        parent[key] = value
    elif how == "delete":
        del parent[key]
    elif how == "nest":
        parent[key] = [[parent[key]]]
    elif how == "wrap":
        parent[key] = {"value": parent[key]}
    return data


@st.composite
def mutated_scenes(draw):
    name = draw(st.sampled_from(sorted(SCENES)))
    data = copy.deepcopy(SCENES[name])
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p, _v in _paths(data) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        how = draw(st.sampled_from(["replace", "replace", "delete", "nest", "wrap"]))
        data = _mutate(data, path, how, draw(values))
    return data


def _toml_text(data) -> str | None:
    try:
        return tomli_w.dumps(data)
    except (TypeError, ValueError):  # nan in a key place, a None, ...: not writable as TOML
        return None


@fuzz(120)
@given(data=mutated_scenes(), as_json=st.booleans(), duplicate=st.booleans())
def test_mutated_scene_files_end_cleanly(tmp_path_factory, data, as_json: bool,
                                         duplicate: bool):
    folder = tmp_path_factory.mktemp("scene")
    if as_json:
        text = json.dumps(data, indent=1, allow_nan=True)
        if duplicate and text.startswith("{\n"):
            text = '{\n "render": {},' + text[1:]  # a duplicated key when render is there
        path = folder / "case.json"
    else:
        text = _toml_text(data)
        if text is None:
            return
        if duplicate:
            text += "\n" + text.split("\n", 1)[0] + "\n"  # the first line again
        path = folder / "case.toml"
    path.write_text(text, encoding="utf-8")
    assert_clean(run_main("info", path.name, cwd=folder))


@fuzz(60)
@given(cut=st.integers(0, 10_000), insert=st.binary(max_size=8), at=st.integers(0, 10_000),
       name=st.sampled_from(sorted(SCENES)), as_json=st.booleans())
def test_truncated_and_corrupted_scene_text_ends_cleanly(tmp_path_factory, cut: int,
                                                         insert: bytes, at: int, name: str,
                                                         as_json: bool):
    folder = tmp_path_factory.mktemp("text")
    raw = (json.dumps(SCENES[name]) if as_json else tomli_w.dumps(SCENES[name])).encode()
    raw = raw[: cut % (len(raw) + 1)]
    at = at % (len(raw) + 1)
    raw = raw[:at] + insert + raw[at:]
    path = folder / ("case.json" if as_json else "case.toml")
    path.write_bytes(raw)
    assert_clean(run_main("info", path.name, cwd=folder))


# ------------------------------------------------------------------------------- model files

OBJ = b"""mtllib cube.mtl
# a unit square, two triangles, with normals and uvs
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vn 0 0 1
usemtl red
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/1/1
usemtl missing
f 1 2 4
"""
MTL = b"""newmtl red
Kd 0.8 0.1 0.1
Ks 0.5 0.5 0.5
Ns 40
d 0.5
Ni 1.5
illum 4
map_Kd tex.png
"""


@st.composite
def damaged(draw, original: bytes):
    raw = original[: draw(st.integers(0, len(original)))]
    for _ in range(draw(st.integers(0, 4))):
        at = draw(st.integers(0, len(raw)))
        kind = draw(st.sampled_from(["insert", "flip", "delete", "number"]))
        if kind == "insert":
            raw = raw[:at] + draw(st.binary(max_size=6)) + raw[at:]
        elif kind == "flip" and raw:
            at = min(at, len(raw) - 1)
            raw = raw[:at] + bytes([draw(st.integers(0, 255))]) + raw[at + 1:]
        elif kind == "delete":
            raw = raw[:at] + raw[at + draw(st.integers(0, 5)):]
        else:
            number = draw(st.sampled_from([b"1e400", b"-0", b"nan", b"9" * 40, b"0", b"-9",
                                           b"99999999999999999999", b"1/2/3/4", b"-2147483649"]))
            raw = raw[:at] + b" " + number + b" " + raw[at:]
    return raw


@fuzz(150)
@given(obj=damaged(OBJ), mtl=damaged(MTL), through_cli=st.booleans())
def test_damaged_obj_and_mtl_files_end_cleanly(tmp_path_factory, obj: bytes, mtl: bytes,
                                               through_cli: bool):
    folder = tmp_path_factory.mktemp("obj")
    (folder / "cube.obj").write_bytes(obj)
    (folder / "cube.mtl").write_bytes(mtl)
    if through_cli:
        assert_clean(run_main("info", "cube.obj", cwd=folder))
        return
    try:
        mesh = load_mesh(folder / "cube.obj")
    except SceneError as exc:
        assert "\n" not in str(exc)
    else:
        assert mesh.faces.shape[1] == 3 and len(mesh.face_material) == len(mesh.faces)


@fuzz(40)
@given(raw=st.binary(max_size=300), suffix=st.sampled_from([".obj", ".ply", ".stl", ".off",
                                                             ".gltf", ".glb"]))
def test_random_bytes_as_a_model_end_cleanly(tmp_path_factory, raw: bytes, suffix: str):
    folder = tmp_path_factory.mktemp("bytes")
    (folder / f"model{suffix}").write_bytes(raw)
    assert_clean(run_main("info", f"model{suffix}", cwd=folder))


# ------------------------------------------------------------------------------ command options

SIZE = st.sampled_from(["-3", "0", "1", "3", "x", "", "1e9", "200000", "2.5"])
OPTIONS = {
    "render": [
        ("--width", SIZE), ("--height", SIZE),
        ("--samples", st.sampled_from(["0", "1", "2", "x", "5000"])),
        ("--max-depth", st.sampled_from(["-1", "0", "2", "65"])),
        ("--threads", st.sampled_from(["-1", "0", "1", "2", "2000"])),
        ("--seed", st.sampled_from(["-1", "0", "7", str(2**40)])),
        ("--aov", st.sampled_from(["depth", "normal,id", "foo", "", "[/bold]", ":100:"])),
        ("--bit-depth", st.sampled_from(["8", "16", "0", "x"])),
        ("--transfer", st.sampled_from(["srgb", "linear", "[red]x", "gamma"])),
        ("-o", st.sampled_from(["o.png", "o.jpg", "o.exr", "o.pfm", "o.npy", "o.txt", "sub",
                                "nowhere/o.png", "scene.toml", "[/bold].png", "x" * 300 + ".png",
                                ".png", "o.PNG"])),
        ("--quiet", None), ("--bogus", None),
    ],
    "info": [("--bogus", None)],
    "export": [
        ("--format", st.sampled_from(["pov", "obj", "[b]"])), ("--width", SIZE),
        ("--height", SIZE),
        ("-o", st.sampled_from(["o.pov", "scene.toml", "sub", "nowhere/o.pov", "x" * 300])),
    ],
    "bench": [("--scene", st.sampled_from(["nope", "[/bold]", ":100:"])),
              ("--runs", st.sampled_from(["0", "-1", "x"])),
              ("--threads", st.sampled_from(["x", "0", "-2"])),
              ("--size", st.sampled_from(["0x0", "axb", "-1x4"]))],
}


@st.composite
def command_lines(draw):
    command = draw(st.sampled_from(sorted(OPTIONS)))
    args = [command]
    if command != "bench" and draw(st.booleans()):
        args.append(draw(st.sampled_from(["scene.toml", "missing.toml", "scene.txt", "sub",
                                          "[/bold].toml"])))
    for option, value in draw(st.lists(st.sampled_from(OPTIONS[command]), max_size=4,
                                       unique_by=lambda o: o[0])):
        args.append(option)
        if value is not None:
            args.append(draw(value))
    if command == "bench" and len(args) == 1:
        args += ["--scene", "nope"]  # never a real benchmark run here
    if command == "render":  # small images only: the random part is the options
        for option in ("--width", "--height"):
            if option not in args:
                args += [option, "3"]
    return args


@fuzz(60)
@given(args=command_lines())
def test_random_command_lines_end_cleanly(tmp_path_factory, args: list[str]):
    folder = tmp_path_factory.mktemp("cli")
    (folder / "scene.toml").write_text(SCENE)
    (folder / "sub").mkdir()
    before = (folder / "scene.toml").read_bytes()
    assert_clean(run_main(*args, cwd=folder))
    assert (folder / "scene.toml").read_bytes() == before  # never written over


@pytest.mark.parametrize("args", [["render", "--width"], ["--nope"], ["render", "a", "b"]])
def test_usage_mistakes_end_cleanly(tmp_path: Path, args: list[str]):
    assert_clean(run_main(*args, cwd=tmp_path))
