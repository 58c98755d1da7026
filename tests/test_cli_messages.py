"""Messages that name the key, the place and the problem in one line: a missing mesh inside
a CSG object, a gather radius too small to mean anything, memory bounded by the process's own
limit (``ulimit -v``), CSG trees too big or holding a light, ``bench --size`` beyond the
limits; and what ``whitted info`` says of anti-aliasing, focal blur and caustics."""

from __future__ import annotations

import resource
import subprocess
import sys
import warnings

import pytest

from cli_run import one_line_error, run_main
from whitted.compile.photon_map import check_photon_memory, check_radius, smallest_radius
from whitted.compile.scene import compile_scene
from whitted.errors import OutputError, SceneError
from whitted.files import memory as memory_module
from whitted.files.memory import memory_room
from whitted.output import safety
from whitted.scene import Scene, load_scene
from whitted.scene.lights import PointLight
from whitted.scene.scene import CausticsSettings
from whitted.scene.shapes import CSG, Sphere

CSG_MESH = """[render]
width = 8
height = 6

[[objects]]
type = "csg"
operation = "difference"

[[objects.objects]]
type = "box"
min = [-1, -1, -1]
max = [1, 1, 1]

[[objects.objects]]
type = "mesh"
file = "missing.obj"
"""


def test_a_missing_mesh_inside_csg_is_named_by_line_and_key(tmp_path):
    (tmp_path / "csg.toml").write_text(CSG_MESH, encoding="utf-8")
    one_line_error(run_main("render", "csg.toml", "-o", "x.png", cwd=tmp_path),
                   "csg.toml:16: objects[0].objects[1].file: no such file: 'missing.obj'")
    one_line_error(run_main("info", "csg.toml", cwd=tmp_path), "objects[0].objects[1].file")


def test_a_gather_radius_below_what_float32_positions_resolve_is_refused():
    scene = Scene.model_validate({"objects": [{"type": "sphere", "center": [0, 1, 0],
                                               "radius": 0.7, "material": "glass"}]})
    compiled = compile_scene(scene)
    floor = smallest_radius(compiled)
    # 16 units in the last place of float32 at the scene's size (1.7: spacing 2^-23 * 1)
    assert floor == pytest.approx(16 * 2.0**-23)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no NumPy warning on the way
        with pytest.raises(SceneError, match=r"^render\.caustics\.radius: 1e-300 is smaller "
                                             r"than the photons' positions can resolve"):
            check_radius(compiled, CausticsSettings(photons=10, radius=1e-300))
        check_radius(compiled, CausticsSettings(photons=10, radius=2 * floor))
        check_radius(compiled, CausticsSettings(photons=10, radius=0.0))  # 0: chosen


def test_memory_room_honours_the_address_space_limit(monkeypatch):
    real = resource.getrlimit

    def limited(kind):
        if kind == resource.RLIMIT_AS:
            return (3 * 2**30, resource.RLIM_INFINITY)
        return real(kind)

    monkeypatch.setattr(resource, "getrlimit", limited)
    monkeypatch.setattr(memory_module, "_free_memory", lambda: 64 * 2**30)
    monkeypatch.setattr(memory_module, "_status_kib",
                        lambda field: 2**30 if field == "VmSize" else 0)
    room = memory_room()
    assert room.bytes == 2 * 2**30  # 3 GiB limit less the 1 GiB the process spans
    assert room.describe() == ("2.0 GiB is left under the process's address-space limit "
                               "of 3.0 GiB (ulimit -v)")
    with pytest.raises(OutputError, match=r"needs about 2\.8 GiB of memory; 2\.0 GiB is left "
                                          r"under the process's address-space limit"):
        safety.check_memory(12000, 15000, "png")
    with pytest.raises(SceneError, match=r"more than half of what this process may take: "
                                         r"2\.0 GiB is left under"):
        check_photon_memory(CausticsSettings(photons=15_000_000))
    # without a limit, the machine's free memory decides
    monkeypatch.setattr(resource, "getrlimit", lambda kind: (resource.RLIM_INFINITY,) * 2)
    assert memory_room().describe() == "64.0 GiB is free"


def test_a_real_ulimit_v_is_read():
    code = ("import resource; resource.setrlimit(resource.RLIMIT_AS, (6 * 2**30, "
            "resource.RLIM_INFINITY)); from whitted.files.memory import memory_room; "
            "room = memory_room(); print(room.bytes, room.what)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=60, check=True)
    room, words = run.stdout.split(" ", 1)
    assert "ulimit -v" in words or "is free" in words
    assert 0 < int(room) <= 6 * 2**30


def test_csg_messages_in_python():
    with pytest.raises(SceneError, match=r"objects\[1\]: a PointLight is a light, not a shape "
                                         r"\(lights go in the scene's lights"):
        CSG(operation="union", objects=[Sphere(center=(0, 0, 0), radius=1.0),
                                        PointLight(position=(0, 1, 0))])
    table = {"type": "sphere", "center": [0, 0, 0], "radius": 1}
    for _ in range(100):
        table = {"type": "csg", "operation": "union", "objects": [table]}
    with pytest.raises(SceneError, match=r"this one has 1 solid in 100 operations, nested 100 "
                                         r"deep$"):
        Scene.model_validate({"objects": [table]}, strict=True)


def test_bench_size_beyond_the_limits_names_the_option(tmp_path):
    line = one_line_error(run_main("bench", "--size", "100000x100000", "--scene", "seed000",
                                   cwd=tmp_path), "--size: 100000x100000 is over 100 megapixels")
    assert "RenderSettings" not in line


INFO = """[render]
width = 8
height = 6

[render.antialias]
threshold = 0.2
max_samples = 25

[render.caustics]
photons = 5000
passes = 2

[camera]
position = [0, 1, 5]
look_at = [0, 0, 0]
aperture = 0.1

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
"""


def test_info_reports_anti_aliasing_focal_blur_and_caustics(tmp_path):
    (tmp_path / "s.toml").write_text(INFO, encoding="utf-8")
    code, out, err = run_main("info", "s.toml", cwd=tmp_path)
    assert code == 0, err
    assert ("anti-aliasing: adaptive (POV-Ray's method 2), threshold 0.2, up to 25 "
            "samples/pixel (2 level(s) of splits)") in out
    focus = load_scene(tmp_path / "s.toml").camera.focus()
    assert f"focal blur: aperture 0.1, in focus at {focus:.4g} (the look_at point)" in out
    assert "caustics: 5,000 photons x 2 pass(es), radius fitted to the photons, alpha 0.7" in out
    # the pixels' corners (9 x 7) up to every point of a grid split twice (33 x 25)
    assert "work: 63 to 825 primary rays" in out and "10,000 photons" in out
    (tmp_path / "plain.toml").write_text("[render]\nwidth = 8\nheight = 6\n", encoding="utf-8")
    out = run_main("info", "plain.toml", cwd=tmp_path)[1]
    assert "anti-aliasing: off (1 sample(s)/pixel" in out
    assert "focal blur: off (camera.aperture = 0)" in out and "caustics: off" in out
