"""What an installed whitted carries besides its code: the example scenes (with their models
and textures) and the benchmark scenes, found by short name, copied out by `whitted examples
DIR` without ever replacing a file; and a core install that names the extra a command needs.
(`make check-wheel`, in CI, builds the real wheel and uses it from a fresh environment.)"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from cli_run import one_line_error, run_main
from whitted.files.shipped import copy_examples, example_names, example_path, shipped_dir

ROOT = Path(__file__).resolve().parent.parent


def run(*args, cwd, pre: str = ""):
    code = (f"import sys\n{pre}\nfrom whitted.cli.main import main\n"
            f"sys.argv = ['whitted', *{list(args)!r}]\nmain()\n")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def shipped_patterns() -> dict[str, tuple[str, ...]]:
    tree = ast.parse((ROOT / "setup.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and [getattr(t, "id", "") for t in node.targets] == [
                "SHIPPED"]:
            return ast.literal_eval(node.value)
    raise AssertionError("setup.py has no SHIPPED")


def test_the_wheel_carries_every_file_the_shipped_scenes_name():
    from whitted.bench.scenes import SCENES, benchmarks_dir
    from whitted.scene import load_scene
    from whitted.scene.writing import named_files

    patterns = shipped_patterns()
    for folder, scenes in (("examples", list(example_names().values())),
                           ("benchmarks", [benchmarks_dir() / s.file for s in SCENES.values()])):
        base = ROOT / folder
        carried = {p.resolve() for pattern in patterns[folder] for p in base.glob(pattern)}
        for path in scenes:
            assert path.resolve() in carried, path
            if folder == "benchmarks":
                continue  # their generated models are written on first use
            scene = load_scene(path)
            for _, name in named_files(scene):
                assert scene.resolve_path(name).resolve() in carried, (path, name)


def test_the_wheel_carries_every_file_the_examples_name_in_their_text():
    """A scene's comment or the models' README names a file (``models/make_cones.py``, the
    script that wrote the cones): an installed whitted's copy of the examples has it too."""
    import re

    base = ROOT / "examples"
    carried = {p.resolve() for pattern in shipped_patterns()["examples"]
               for p in base.glob(pattern)}
    named = 0
    for path in sorted(carried):
        if path.suffix not in (".toml", ".md", ".obj", ".mtl", ".py"):
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        for name in re.findall(r"(?<![\w/.])((?:models|textures)/[\w/.-]+\.[a-z]{2,4})\b",
                               text):
            named += 1
            assert (base / name).resolve() in carried, (path.relative_to(base), name)
    assert named >= 5


def test_examples_by_short_name():
    names = example_names()
    assert "glass_cube" in names and "textured" in names and len(names) >= 10
    assert not any("/" in name for name in names)  # the Stefan cases are not scenes
    assert example_path("glass_cube") == shipped_dir("examples") / "glass_cube.toml"
    for not_a_name in ("", "glass_cube.toml", "../glass_cube", "nonesuch", "models/cow/cow"):
        assert example_path(not_a_name) is None


def test_render_an_example_by_name_and_a_file_wins(tmp_path):
    done = run("render", "lecture_rectangles", "-o", "l.png", "-q", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    (tmp_path / "lecture_rectangles").write_text("not a scene")  # a file of that name wins
    done = run("render", "lecture_rectangles", "-o", "m.png", cwd=tmp_path)
    assert done.returncode == 2 and "unknown scene format" in done.stderr
    done = run("render", "nonesuch", "-o", "n.png", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "nonesuch" in done.stderr


@pytest.mark.parametrize("command", ["render", "export", "sweep", "animate", "info"])
def test_a_misspelt_example_name_gets_the_names_near_it(tmp_path, command):
    line = one_line_error(run_main(command, "glass_cub", cwd=tmp_path), "glass_cub: ")
    assert "did you mean 'glass_cube'?" in line and "`whitted examples` lists them" in line
    line = one_line_error(run_main(command, "qqqq", cwd=tmp_path), "qqqq: no such file")
    assert "did you mean" not in line and "`whitted examples` lists them" in line
    one_line_error(run_main(command, "missing.toml", cwd=tmp_path),
                   "missing.toml: no such file")
    assert not list(tmp_path.iterdir())  # nothing written


def test_a_misspelt_example_name_in_the_editor(tmp_path):
    done = subprocess.run([sys.executable, "-m", "whitted", "gui", "glas_cube"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith("error: glas_cube: ") and "'glass_cube'" in done.stderr


def test_copy_examples_never_replaces_a_file(tmp_path):
    target = tmp_path / "mine"
    target.mkdir()
    (target / "glass_cube.toml").write_text("my own glass cube")
    copied, kept = copy_examples(target)
    assert Path("glass_cube.toml") in kept
    assert (target / "glass_cube.toml").read_text() == "my own glass cube"
    assert Path("models/cow/cow.obj") in copied and Path("textures/earth.png") in copied
    assert (target / "models/cow/cow.obj").read_bytes() == \
        (shipped_dir("examples") / "models/cow/cow.obj").read_bytes()
    again, kept_all = copy_examples(target)
    assert again == [] and len(kept_all) == len(copied) + len(kept)
    assert not list(target.rglob("*.part"))


def test_whitted_examples_command(tmp_path):
    done = run("examples", cwd=tmp_path)
    assert done.returncode == 0 and "glass_cube\n" in done.stdout
    done = run("examples", "ex", cwd=tmp_path)
    assert done.returncode == 0 and "copied" in done.stdout
    done = run("render", "ex/textured.toml", "-W", "24", "-H", "18", "-o", "t.png", "-q",
               cwd=tmp_path)
    assert done.returncode == 0, done.stderr  # the copies find their models and textures
    (tmp_path / "afile").write_text("x")
    for target in ("afile", "afile/sub"):
        done = run("examples", target, cwd=tmp_path)
        assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o555)
    done = run("examples", "ro/ex", cwd=tmp_path)
    if done.returncode != 0:  # (root may write anywhere)
        assert done.returncode == 2 and done.stderr.count("\n") == 1


@pytest.mark.parametrize(("args", "blocked", "extra"), [
    (["stefan", "validate"], "skimage", "whitted[stefan]"),
    (["stefan", "run", "x.toml"], "scipy", "whitted[stefan]"),
    (["animate", "lecture_rectangles", "-o", "f.mp4", "-W", "8", "-H", "8"], "imageio_ffmpeg",
     "whitted[film]"),
])
def test_a_missing_extra_is_one_line_naming_it(tmp_path, args, blocked, extra):
    done = run(*args, cwd=tmp_path, pre=(
        f"sys.modules[{blocked!r}] = None\n"
        "import os; os.environ['PATH'] = '/nonexistent'"))
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and f"install {extra}" in done.stderr
    assert not (tmp_path / "f_frames").exists()  # refused before the first frame


def test_the_core_needs_no_extra(tmp_path):
    """`render`, `info` and `export` import nothing of what the extras bring."""
    code = (
        "import sys\n"
        "for m in ('scipy', 'skimage', 'imageio', 'imageio_ffmpeg', 'matplotlib', 'PySide6',"
        " 'distributed', 'dask'):\n"
        "    sys.modules[m] = None\n"
        "from whitted.cli.main import main\n"
        "sys.argv = ['whitted', *sys.argv[1:]]\n"
        "main()\n")
    for args in (["render", "glass_cube", "-W", "16", "-H", "12", "-o", f"{tmp_path}/c.png", "-q"],
                 ["info", "glass_cube"], ["export", "glass_cube", "-o", f"{tmp_path}/c.pov"]):
        done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True,
                              text=True, timeout=300)
        assert done.returncode == 0, (args, done.stderr)


def test_whitted_examples_takes_o_as_well(tmp_path):
    done = run("examples", "-o", "ex", cwd=tmp_path)
    assert done.returncode == 0 and (tmp_path / "ex/glass_cube.toml").is_file()
    done = run("examples", "a", "-o", "b", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.count("\n") == 1


def test_every_missing_package_of_the_stefan_extra_is_named(tmp_path):
    done = run("stefan", "validate", cwd=tmp_path, pre=(
        "for m in ('scipy', 'skimage', 'matplotlib'):\n    sys.modules[m] = None"))
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "SciPy, scikit-image and Matplotlib" in done.stderr
    code = ("import sys\nsys.modules['PySide6'] = None\nfrom whitted.program import main\n"
            "sys.argv = ['whitted', 'gui']\nmain()\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=300)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert "install whitted[gui]" in done.stderr
