"""The standard benchmark scenes (``benchmarks/*.toml``) and how to load them.

A scene file names its committed models relative to itself (``models/cone_96.obj``) and its
generated ones as ``generated/NAME``: those are written on first use into the bench cache
folder (:func:`whitted.bench.models.bench_cache_dir`) and the name is pointed there.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import SceneError
from ..scene.io import parse_scene_text, scene_from_dict
from ..scene.materials import Material
from ..scene.scene import Scene
from ..scene.shapes import Mesh
from .models import generated_model

GENERATED_PREFIX = "generated/"


@dataclass(frozen=True)
class BenchScene:
    name: str
    file: str
    description: str
    quick: bool = True  # part of `whitted bench --quick` (with small versions of big models)
    mesh_bench: bool = False  # one of the mesh benchmarks; mesh1m is one too

    @property
    def meshes(self) -> bool:
        """A scene of the mesh benchmark: what ``--compare embree`` traces."""
        return self.mesh_bench or self.name == "mesh1m"


SCENES: dict[str, BenchScene] = {
    s.name: s
    for s in (
        BenchScene("seed000", "seed000.toml",
                   "000's timing scene: glass sphere, 14 spheres, plane, 2 point lights, "
                   "4 mesh cones (642 triangles)"),
        BenchScene("softshadow", "softshadow.toml",
                   "seed000 lit by one disk light, 64 shadow samples"),
        BenchScene("ice", "ice.toml",
                   "001's hollow ice block with water and an air bubble, all meshes"),
        BenchScene("mesh1m", "mesh1m.toml",
                   "a generated 1,000,000-triangle height field, one light with shadows"),
        BenchScene("lecture", "lecture.toml", "002's two rectangles"),
        BenchScene("sphere1m", "sphere1m.toml",
                   "a closed bumpy UV sphere of 1,000,000 triangles seen whole, shadows",
                   mesh_bench=True),
        BenchScene("bunny1m", "bunny1m.toml",
                   "the Stanford bunny subdivided to 1,111,216 triangles, shadows",
                   mesh_bench=True),
        BenchScene("vase1m", "vase1m.toml",
                   "a finely revolved vase: 980,000 long thin triangles, shadows",
                   mesh_bench=True),
        BenchScene("instances100", "instances100.toml",
                   "100 instances of a 100,000-triangle torus, shadows", mesh_bench=True),
        BenchScene("csg", "csg.toml",
                   "CSG of analytic solids: differences, an intersection, a half torus, a "
                   "merge of two glass balls"),
        BenchScene("dice100", "dice100.toml",
                   "a hundred dice, each a rounded cube minus 21 pips (23 solids of CSG)"),
        BenchScene("caustics", "caustics.toml",
                   "a glass ball and a glass slab on a floor, a directional and a point "
                   "light: caustics by photon mapping (100,000 photons)"),
    )
}


def benchmarks_dir() -> Path:
    """The ``benchmarks/`` folder: the installed package's, or the checkout's (found from
    this file in an editable install or a source tree), else ``./benchmarks``."""
    from ..files.shipped import shipped_dir

    return shipped_dir("benchmarks") or Path.cwd() / "benchmarks"


def pick_scenes(names: list[str] | None, quick: bool = False) -> list[BenchScene]:
    """The scenes named (all when none; only the quick ones with ``quick``)."""
    if not names:
        return [s for s in SCENES.values() if s.quick or not quick]
    unknown = [n for n in names if n not in SCENES]
    if unknown:
        raise SceneError(f"unknown benchmark scene {unknown[0]!r} (known: {', '.join(SCENES)})")
    return [SCENES[n] for n in names]


def load_bench_scene(name: str, folder: Path | None = None, quick: bool = False) -> Scene:
    """Benchmark scene ``name`` with every file name absolute and generated models written
    (their small versions with ``quick``). Raises ``models.MissingSourceModel`` when a model
    needs a file this machine does not have (the bunny)."""
    spec = SCENES[name]
    path = (folder or benchmarks_dir()) / spec.file
    if not path.is_file():
        raise SceneError("no such benchmark scene file (whitted's benchmark scenes are not "
                         "installed here)", file=str(path))
    text = path.read_text(encoding="utf-8")
    scene = scene_from_dict(parse_scene_text(text, ".toml", str(path)), file=str(path),
                            text=text).with_base_dir(path.parent)
    return with_absolute_files(scene, quick)


def with_absolute_files(scene: Scene, quick: bool = False) -> Scene:
    """The scene with model and texture file names absolute (generated ones written), so it
    can be saved anywhere and still find them."""
    for obj in scene.objects:
        if isinstance(obj, Mesh) and obj.file is not None:
            if obj.file.startswith(GENERATED_PREFIX):
                obj.file = str(generated_model(obj.file[len(GENERATED_PREFIX):], quick=quick))
            else:
                obj.file = str(scene.resolve_path(obj.file))
        material = obj.material
        if isinstance(material, Material):
            _absolute_texture(scene, material)
    for material in scene.materials.values():
        _absolute_texture(scene, material)
    return scene


def _absolute_texture(scene: Scene, material: Material) -> None:
    texture = material.texture
    if texture is not None and getattr(texture, "file", None):
        texture.file = str(scene.resolve_path(texture.file))


def has_meshes(scene: Scene) -> bool:
    return any(isinstance(obj, Mesh) for obj in scene.objects)
