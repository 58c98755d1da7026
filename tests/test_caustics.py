"""Caustics by photon mapping (docs/caustics.md): the physics checked against exact optics,
with the expected values computed here from the exact Fresnel equations (whitted's),
determinism, and the settings."""

from __future__ import annotations

import math

import numpy as np
import pytest

from whitted import render
from whitted.compile.photon_map import (
    GRID_SHIFT,
    check_photon_memory,
    fitted_radius,
    irradiance,
    pass_radii,
    scene_photon_map,
)
from whitted.errors import SceneError
from whitted.kernels.layout import PHOTON_POWER
from whitted.render.api import RenderJob
from whitted.scene.scene import CausticsSettings, Scene

GLASS = {"color": [1, 1, 1], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kr": 0.0, "kt": 1.0,
         "ior": 1.5, "fresnel": True}
SUN = {"type": "directional", "direction": [0, -1, 0], "intensity": 1.0}


def scene_of(objects, photons=100_000, passes=1, radius=0.0, lights=None, size=(8, 8),
             camera=None):
    data = {
        "render": {"width": size[0], "height": size[1], "transfer": "linear", "max_depth": 8,
                   "caustics": {"photons": photons, "passes": passes, "radius": radius}},
        "materials": {"floor": {"color": [1, 1, 1], "ka": 0.0, "kd": 1.0, "ks": 0.0}},
        "lights": lights or [SUN],
        "objects": [{"type": "plane", "material": "floor"}] + objects,
    }
    if camera:
        data["camera"] = camera
    return Scene.model_validate(data)


def fresnel_air(cos_air, n):
    """The exact Fresnel reflectance for unpolarised light at a glass/air surface, either way
    through it (whitted's, kernels/integrator.py)."""
    cos_glass = np.sqrt(1 - (1 - cos_air * cos_air) / (n * n))
    rs = (cos_air - n * cos_glass) / (cos_air + n * cos_glass)
    rp = (cos_glass - n * cos_air) / (cos_glass + n * cos_air)
    return 0.5 * (rs * rs + rp * rp)


def caustic_power(lights):
    """The power of the caustic photons (the shadow photons carry less than 0)."""
    power = lights.photons[:, PHOTON_POWER].astype(np.float64)
    return power[power > 0].sum()


def floor_points(half, count):
    xs = np.linspace(-half, half, count)
    return np.array([[x, 0.0, z] for x in xs for z in xs])


def test_slab_passes_its_transmittance_under_a_directional_light():
    # normal incidence: F = r0 = 0.04 at each face; with the internal reflections the slab
    # passes T = (1 - F)^2 (1 + F^2 + F^4 + ...) = (1 - F) / (1 + F) = 0.923077
    f = fresnel_air(1.0, 1.5)
    expected = (1 - f) / (1 + f)
    assert expected == pytest.approx(0.923077, abs=1e-6)
    scene = scene_of([{"type": "box", "min": [-2, 1, -2], "max": [2, 1.5, 2],
                       "material": GLASS}], photons=200_000)
    _, lights, stats = scene_photon_map(scene, threads=2)
    e = irradiance(lights, floor_points(1.0, 7), [0, 1, 0])[:, 0]
    assert e.mean() == pytest.approx(expected, rel=0.02)
    assert np.all(np.abs(e / expected - 1) < 0.1)  # no blotches
    assert stats.targets == 1 and stats.stored > 0


def test_a_body_of_ior_1_leaves_the_floor_as_lit_as_without_it():
    clear = dict(GLASS, ior=1.0, fresnel=False)
    scene = scene_of([{"type": "sphere", "center": [0, 2, 0], "radius": 1.0,
                       "material": clear}])
    _, lights, _ = scene_photon_map(scene, threads=2)
    e = irradiance(lights, floor_points(0.6, 5), [0, 1, 0])[:, 0]
    # the unoccluded floor's irradiance from the unit sun straight above is 1
    assert e.mean() == pytest.approx(1.0, rel=0.02)
    assert np.all(np.abs(e - 1.0) < 0.05)
    # and the photons arrive only on the lit side
    assert irradiance(lights, [[0, 0, 0]], [0, -1, 0])[0, 0] == 0.0


def ball_power_on_floor(n, steps=400_000):
    """Fraction of the power through a glass ball's cross-section that reaches the floor
    below, by the exact Fresnel equations: the part reflected by the outer surface downward
    (incidence past 45 degrees) plus the part leaving after k internal reflections whose
    deviation 2(i - t) + k(pi - 2t) still points down."""
    b = (np.arange(steps) + 0.5) / steps
    cos_i = np.sqrt(1 - b * b)
    i = np.arcsin(b)
    t = np.arcsin(b / n)
    f = fresnel_air(cos_i, n)
    total = np.sum(f * 2 * b * (np.cos(math.pi - 2 * i) > 0)) / steps
    for k in range(12):
        deviation = 2 * (i - t) + k * (math.pi - 2 * t)
        total += np.sum((1 - f) ** 2 * f ** k * 2 * b * (np.cos(deviation) > 0)) / steps
    return total


def test_glass_ball_total_caustic_power():
    expected = ball_power_on_floor(1.5)
    assert expected == pytest.approx(0.91272, abs=2e-4)
    scene = scene_of([{"type": "sphere", "center": [0, 3, 0], "radius": 1.0,
                       "material": GLASS}], photons=200_000)
    _, lights, _ = scene_photon_map(scene, threads=2)
    power = lights.photons[:, PHOTON_POWER].astype(np.float64)
    assert power[power > 0].sum() / math.pi == pytest.approx(expected, rel=0.02)
    # the shadow photons take away the unit sun's power through the cross-section, pi
    assert power[power < 0].sum() == pytest.approx(-math.pi, rel=0.01)


def test_glass_ball_focuses_on_its_axis_at_the_paraxial_focus():
    n, radius_ball = 1.5, 1.0
    f = n * radius_ball / (2 * (n - 1))  # 1.5 from the centre
    r = 0.02
    scene = scene_of([{"type": "sphere", "center": [0, f, 0], "radius": radius_ball,
                       "material": GLASS}], photons=300_000, radius=r)
    _, lights, _ = scene_photon_map(scene, threads=2)
    pts = floor_points(0.2, 41)  # a 0.01 grid on the floor at the paraxial focus
    e = irradiance(lights, pts, [0, 1, 0])[:, 0]
    brightest = pts[np.argmax(e)]
    assert math.hypot(brightest[0], brightest[2]) <= r
    # along the axis, the irradiance falls beyond the paraxial focus (spherical aberration
    # brings the marginal rays to the axis before it, never after)
    axis = []
    for h in (f - 0.1, f, f + 0.1):
        s = scene_of([{"type": "sphere", "center": [0, h, 0], "radius": radius_ball,
                       "material": GLASS}], photons=300_000, radius=r)
        axis.append(irradiance(scene_photon_map(s, threads=2)[1], [[0, 0, 0]], [0, 1, 0])[0, 0])
    assert axis[0] > axis[1] > 3 * axis[2]


def test_point_light_photons_match_the_direct_term_through_an_ior_1_body():
    clear = dict(GLASS, ior=1.0, fresnel=False)
    lights = [{"type": "point", "position": [0, 6, 0], "intensity": 2.0,
               "falloff": "inverse_square"}]
    # the floor is 1.5 times as far from the light as the ball: photons spread 2.25 times
    # as thin there as on the ball, so a radius gathering enough of them
    scene = scene_of([{"type": "sphere", "center": [0, 2, 0], "radius": 1.0,
                       "material": clear}], lights=lights, radius=0.08)
    _, arrays, _ = scene_photon_map(scene, threads=2)
    pts = floor_points(0.5, 5)
    e = irradiance(arrays, pts, [0, 1, 0])[:, 0]
    d2 = pts[:, 0] ** 2 + pts[:, 2] ** 2 + 36.0
    direct = 2.0 / d2 * (6.0 / np.sqrt(d2))  # I / d^2 * cos
    assert np.all(np.abs(e / direct - 1) < 0.05)
    assert e.mean() / direct.mean() == pytest.approx(1.0, rel=0.02)


def test_radius_shrinks_as_progressive_photon_mapping_prescribes():
    r = pass_radii(0.1, 4, 0.7)
    assert r[0] == 0.1
    assert r[1] ** 2 == pytest.approx(0.01 * 1.7 / 2)
    assert r[2] ** 2 == pytest.approx(0.01 * 1.7 / 2 * 2.7 / 3)
    assert r[3] ** 2 == pytest.approx(0.01 * 1.7 / 2 * 2.7 / 3 * 3.7 / 4)


def _fitted_radius_by_counting(positions, guess, neighbours=256):
    """fitted_radius's definition, photon by photon: the median over the photons of the
    count of photons in their cell (a dictionary of cells), twice."""
    r = guess
    pos = positions.astype(np.float64)
    for _ in range(2):
        h = 2.0 * r
        cells = [tuple(c) for c in np.floor(pos / h + GRID_SHIFT).astype(np.int64)]
        keys = [(x * 73856093) ^ (y * 19349663) ^ (z * 83492791) for x, y, z in cells]
        count = {}
        for key in keys:
            count[key] = count.get(key, 0) + 1
        density = float(np.median([count[key] for key in keys])) / (h * h)
        r = min(4.0 * guess, max(guess / 8.0, math.sqrt(neighbours / (math.pi * density))))
    return r


def test_the_fitted_radius_counts_each_photons_cell():
    """A worked case: 1,024 photons on the floor (y = 0), 4 in each of 256 cells of side
    2 x 0.05 (the guess): density 4 / 0.01 = 400 a unit area, so the radius gathering 256
    photons is sqrt(256 / (400 pi)) = 0.451, kept within 4 x the guess (0.2); the second
    round's cells of side 0.4 hold 64 photons (576 of the 1,024 photons are in such cells,
    the others at the edges): the same density, 0.2 again. And random sets of photons give
    the definition's radius, bit for bit."""
    side = np.arange(16) * 0.1 + 0.01  # the cells 0.1 wide: [k - 0.5, k + 0.5) x 0.1
    grid = np.array([[x + dx, 0.0, z + dz] for x in side for z in side
                     for dx in (0.02, 0.03) for dz in (0.02, 0.03)], np.float32)
    assert len(grid) == 1024
    assert fitted_radius(grid, 0.05) == 0.2
    rng = np.random.default_rng(7)
    for trial in range(40):
        n = int(rng.integers(256, 3000))
        spread = rng.uniform(0.05, 3.0)
        pos = np.c_[rng.normal(0, spread, n), np.zeros(n) if trial % 2 else
                    rng.normal(0, spread, n), rng.normal(0, spread, n)].astype(np.float32)
        guess = float(rng.uniform(0.005, 1.0))
        assert fitted_radius(pos, guess) == _fitted_radius_by_counting(pos, guess), trial
    assert fitted_radius(pos[:255], 0.3) == 0.3  # too few photons to fit: the guess


def test_photon_map_is_the_same_on_any_number_of_threads():
    scene = scene_of([{"type": "sphere", "center": [0, 2, 0], "radius": 1.0,
                       "material": GLASS}], photons=20_000, passes=2)
    one = scene_photon_map(scene, threads=1)[1]
    three = scene_photon_map(scene, threads=3)[1]
    assert np.array_equal(one.photons, three.photons)
    assert np.array_equal(one.photon_cells, three.photon_cells)
    other_seed = scene_photon_map(scene.with_settings(seed=1), threads=1)[1]
    assert not np.array_equal(one.photons, other_seed.photons)


def test_render_with_caustics_shows_them_and_is_thread_independent():
    camera = {"position": [0, 5, 5], "look_at": [0, 0, 0], "fov": 40.0}
    scene = scene_of([{"type": "sphere", "center": [0, 2.5, 0], "radius": 1.0,
                       "material": GLASS}], photons=50_000, size=(40, 30), camera=camera)
    a = render(scene, threads=1).pixels
    b = render(scene, threads=2).pixels
    assert np.array_equal(a, b)
    # a still split in bands of rows, as the render farm's workers render it
    bands = [RenderJob(scene, threads=2, rows=rows).run().pixels for rows in ((0, 13), (13, 30))]
    assert np.array_equal(np.concatenate([bands[0][:13], bands[1][13:]]), a)
    plain = render(scene.with_settings(caustics=CausticsSettings())).pixels
    # without caustics the floor under a clear ball is lit through it (kt·colour = 1): the
    # floor is 1 everywhere; with them the shadow ray stops at the ball and the light
    # arrives as photons, focused in the middle of its shadow and missing at its rim
    assert plain.max() == 1.0
    assert a.max() > 1.3 and (a < 0.5).sum() > (plain < 0.5).sum() + 20
    assert not np.array_equal(a, plain)


def test_no_photons_is_the_renderer_without_caustics():
    camera = {"position": [0, 5, 5], "look_at": [0, 0, 0], "fov": 40.0}
    scene = scene_of([{"type": "sphere", "center": [0, 2.5, 0], "radius": 1.0,
                       "material": GLASS}], photons=0, size=(20, 15), camera=camera)
    assert scene.render.caustics == CausticsSettings()
    image = render(scene)
    assert image.meta["stats"].photons is None


@pytest.mark.parametrize("key, value", [("photons", -1), ("photons", 10**9),
                                        ("passes", 0), ("radius", -1.0),
                                        ("radius", float("nan")), ("alpha", 0.0),
                                        ("alpha", 1.5), ("photons", "many"),
                                        ("colour", 1)])
def test_bad_caustics_settings_are_refused(key, value):
    with pytest.raises(SceneError):
        Scene.model_validate({"render": {"caustics": {key: value}}}, strict=True)


def test_a_photon_map_too_big_for_memory_is_refused():
    with pytest.raises(SceneError, match=r"render\.caustics"):
        check_photon_memory(CausticsSettings(photons=50_000_000, passes=4096))


def test_the_photon_maps_memory_counts_each_threads_slots_not_every_photons():
    """1,000,000 photons on 2 threads: 16 calls of 62,500 photons, each thread's 6 slots of
    40 bytes for the photons of one call (30,000,000 bytes), a pass's counts (4,000,000), the
    photons stored, three copies of 40 bytes and 16 bytes of keys and table each
    (136,000,000). On one thread: 8 calls of 125,000 photons, the same 30,000,000 bytes of
    slots; two passes store twice the photons."""
    assert check_photon_memory(CausticsSettings(photons=1_000_000), threads=2) == 170_000_000
    assert check_photon_memory(CausticsSettings(photons=1_000_000, passes=2), threads=1) \
        == 30_000_000 + 4_000_000 + 272_000_000


def test_disk_light_casts_a_soft_caustic_of_the_same_power():
    point = [{"type": "point", "position": [0, 6, 0], "intensity": 1.0,
              "falloff": "inverse_square"}]
    disk = [{"type": "disk", "center": [0, 6, 0], "radius": 1.0, "intensity": 1.0,
             "falloff": "inverse_square"}]
    ball = [{"type": "sphere", "center": [0, 2, 0], "radius": 1.0, "material": GLASS}]
    _, sharp, _ = scene_photon_map(scene_of(ball, lights=point, radius=0.02), threads=2)
    _, soft, _ = scene_photon_map(scene_of(ball, lights=disk, radius=0.02), threads=2)
    power = [caustic_power(a) for a in (sharp, soft)]
    # each point of the disk (radius 1, 4 above the ball's centre) shines on the ball as a
    # point light of its share of the intensity would: the power goes with the solid angle,
    # ~ 1 / (16 + rho^2), whose mean over the disk is ln(17 / 16): 0.970 of the centre's
    assert power[1] == pytest.approx(power[0] * 16 * math.log(17 / 16), rel=0.01)
    peak = [irradiance(a, [[0, 0, 0]], [0, 1, 0])[0, 0] for a in (sharp, soft)]
    assert peak[1] < 0.5 * peak[0]  # the disk's focus is spread: a soft caustic


def test_meshes_traced_as_instances_focus_like_flattened_ones():
    from whitted.compile.params import render_params
    from whitted.compile.photon_map import photon_lights
    from whitted.compile.scene import compile_scene

    # a glass icosphere-like mesh: a UV sphere of triangles
    n_lat, n_lon = 16, 32
    verts = [[0, 1, 0]]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            verts.append([math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)])
    verts.append([0, -1, 0])
    faces = [[0, 1 + (j + 1) % n_lon, 1 + j] for j in range(n_lon)]
    for i in range(n_lat - 2):
        for j in range(n_lon):
            a, b = 1 + i * n_lon + j, 1 + i * n_lon + (j + 1) % n_lon
            faces += [[a, b, b + n_lon], [a, b + n_lon, a + n_lon]]
    last = len(verts) - 1
    base = 1 + (n_lat - 2) * n_lon
    faces += [[last, base + j, base + (j + 1) % n_lon] for j in range(n_lon)]
    mesh = {"type": "mesh", "vertices": verts, "faces": faces, "material": GLASS,
            "transform": {"translate": [0, 2.5, 0]}}
    scene = scene_of([mesh], photons=50_000)
    powers = []
    for limit in (10**6, 0):  # flattened into the scene BVH, then instanced
        compiled = compile_scene(scene, flatten_limit=limit)
        params = render_params(scene, compiled, scene.render)
        lights = photon_lights(compiled, params, scene.render.caustics, 2)
        powers.append(caustic_power(lights))
    assert powers[0] > 0.8 * math.pi  # the power through the cross-section, mostly
    assert powers[1] == pytest.approx(powers[0], rel=1e-3)


def test_water_inside_ice_passes_light_through_both_media():
    ice = {"color": [1, 1, 1], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kr": 0.0, "kt": 1.0,
           "ior": 1.309, "fresnel": True}
    water = dict(ice, ior=1.333, attenuation=[0.5, 0.5, 0.5])
    objects = [{"type": "box", "min": [-2, 1, -2], "max": [2, 3, 2], "material": ice},
               {"type": "box", "min": [-1.5, 1.5, -1.5], "max": [1.5, 2.5, 1.5],
                "material": water}]
    _, lights, _ = scene_photon_map(scene_of(objects, photons=200_000), threads=2)
    e = irradiance(lights, floor_points(0.5, 5), [0, 1, 0])[:, 0].mean()
    # straight down through four faces: ice (n 1.309) from air, water from ice, ice from
    # water, air from ice; 1 of water absorbs exp(-0.5); internal reflections between the
    # faces add (1 + F^2 ...) for each, less than 0.5 % here and left out
    r = [((a - b) / (a + b)) ** 2 for a, b in ((1, 1.309), (1.309, 1.333), (1.333, 1.309),
                                                (1.309, 1))]
    expected = math.prod(1 - f for f in r) * math.exp(-0.5)
    assert e == pytest.approx(expected, rel=0.02)


def test_export_writes_photons_blocks():
    from whitted.export.pov import scene_to_pov

    scene = scene_of([{"type": "sphere", "center": [0, 2, 0], "radius": 1.0,
                       "material": GLASS}], photons=1000, passes=3, radius=0.05)
    text = scene_to_pov(scene)
    assert "photons { count 3000 autostop 0 jitter 0.4" in text
    assert "radius 0.05" in text
    assert "photons { target reflection on refraction on collect off }" in text
    plain = scene_to_pov(scene.with_settings(caustics=CausticsSettings()))
    assert "photons" not in plain


def test_export_keeps_the_photon_count_within_what_povray_reads():
    # photons x passes past 2^31 - 1 wrapped round in POV-Ray's C int (it shot 1 photon):
    # the count is clipped to the largest it holds, and a comment line says so
    from whitted.export.pov import POV_MAX_COUNT, scene_to_pov

    assert POV_MAX_COUNT == 2_147_483_647
    ball = [{"type": "sphere", "center": [0, 2, 0], "radius": 1.0, "material": GLASS}]
    # 3.2e9, exactly 2^31, and 2048 short of 2^31 - 1
    for photons, passes in ((50_000_000, 64), (1_048_576, 2048), (1_048_575, 2048)):
        text = scene_to_pov(scene_of(ball, photons=photons, passes=passes))
        count = min(photons * passes, POV_MAX_COUNT)
        assert f"photons {{ count {count} autostop 0" in text
        notes = [line for line in text.splitlines() if "POV-Ray's count holds" in line]
        if photons * passes > POV_MAX_COUNT:
            assert notes == [f"  // whitted shoots {photons * passes} photons ({photons} x "
                             f"{passes} passes); POV-Ray's count holds at most 2147483647"]
        else:
            assert count == 2_147_481_600 and notes == []


PRESET_GLASS = {"preset": "glass"}  # kr 0.05, kt 0.95, ior 1.5, fresnel


def test_export_filter_makes_povray_transmit_what_whitted_does():
    # POV-Ray's conserve_energy passes filter * (1 - kr - kt F) where whitted passes
    # kt (1 - F): for the glass preset (kr + kt = 1) a filter of 1 is equal at every F, the
    # old filter kt = 0.95 passed 0.95 (1 - F) * 0.95, 5 % less a surface
    from whitted.export.pov import pov_filter, scene_to_pov
    from whitted.scene.materials import Material

    glass = Material(preset="glass")
    assert pov_filter(glass) == 1.0
    for f in (0.0, 0.04, 0.3, 1.0):
        assert pov_filter(glass) * (1 - glass.kr - glass.kt * f) == pytest.approx(
            glass.kt * (1 - f))
    ice = Material(preset="ice")  # kr + kt = 0.93: equal at normal incidence
    f0 = ((ice.ior - 1) / (ice.ior + 1)) ** 2
    assert pov_filter(ice) * (1 - ice.kr - ice.kt * f0) == pytest.approx(ice.kt * (1 - f0))
    assert pov_filter(Material(kt=0.5, kr=0.0)) == 0.5  # no Fresnel: the filter is kt
    scene = scene_of([{"type": "sphere", "center": [0, 2, 0], "radius": 1.0,
                       "material": PRESET_GLASS}])
    assert "rgbf <1, 1, 1, 1>" in scene_to_pov(scene)
    # without caustics POV-Ray's shadow rays pass the filter: it stays kt, as whitted's
    plain = scene_to_pov(scene.with_settings(caustics=CausticsSettings()))
    assert "rgbf <1, 1, 1, 0.95>" in plain


def _povray_floor(scene, tmp_path, size=32):
    """POV-Ray's linear image (red channel) of ``scene`` exported by whitted, read from a
    16-bit PPM."""
    import shutil
    import subprocess

    from whitted.export.pov import scene_to_pov

    if shutil.which("povray") is None:
        pytest.skip("povray is not installed")
    pov = tmp_path / "s.pov"
    pov.write_text(scene_to_pov(scene))
    out = tmp_path / "s.ppm"
    subprocess.run(["povray", f"+I{pov}", f"+O{out}", f"+W{size}", f"+H{size}", "-A", "-D",
                    "-P", "+FP16", "+WT2", "-V", "File_Gamma=1.0"], capture_output=True,
                   check=True, timeout=120)
    data = out.read_bytes()
    header, pos = [], 0
    while len(header) < 4:  # P6, width, height, maxval, with '#' comment lines between
        end = data.index(b"\n", pos)
        line = data[pos:end].split(b"#")[0]
        header += line.split()
        pos = end + 1
    assert header == [b"P6", str(size).encode(), str(size).encode(), b"65535"]
    pixels = np.frombuffer(data[pos:pos + size * size * 6], ">u2").reshape(size, size, 3)
    return pixels[..., 0] / 65535.0


def test_povray_given_the_export_passes_the_slabs_transmittance(tmp_path):
    # the glass preset slab under a unit sun, POV-Ray's camera between slab and floor
    # (looking down, so camera rays do not cross the slab): the floor is lit only by
    # photons. By whitted's model each face passes kt (1 - F) = 0.912 and reflects
    # kr + kt F = 0.088 (F = 0.04 at normal incidence, Schlick and exact Fresnel alike):
    # T = t^2 / (1 - R^2) = 0.838235. The old export (filter kt) gave 0.750.
    t, r = 0.95 * 0.96, 0.05 + 0.95 * 0.04
    expected = t * t / (1 - r * r)
    assert expected == pytest.approx(0.838235, abs=1e-6)
    camera = {"position": [0, 0.5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
              "projection": "orthographic", "ortho_height": 2.0}
    scene = scene_of([{"type": "box", "min": [-3, 1, -3], "max": [3, 1.5, 3],
                       "material": PRESET_GLASS}], photons=50_000, camera=camera)
    floor = _povray_floor(scene, tmp_path)
    assert floor.mean() == pytest.approx(expected, rel=0.02)
    # and whitted's own photons, gathered the same way
    _, lights, _ = scene_photon_map(scene, threads=2)
    e = irradiance(lights, floor_points(0.9, 7), [0, 1, 0])[:, 0]
    assert e.mean() == pytest.approx(expected, rel=0.02)


def test_no_rim_at_the_edge_of_a_transparent_bodys_shadow():
    # a glass slab (x < 0) under a unit sun: the floor under it gets T = 0.923 (photons),
    # beside it 1 (direct). A profile across the shadow's edge, seen from between slab and
    # floor, must step from T to 1 with no overshoot or undershoot beyond the noise. Before
    # the shadow photons, the gather radius straddling the edge gave a dark rim inside
    # (photons missing beyond the edge, ~T/2) and a bright one outside (1 + ~T/2).
    f = fresnel_air(1.0, 1.5)
    t = (1 - f) / (1 + f)
    r = 0.03
    camera = {"position": [0, 0.5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
              "projection": "orthographic", "ortho_height": 0.125}
    scene = scene_of([{"type": "box", "min": [-1, 1, -0.5], "max": [0, 1.2, 0.5],
                       "material": GLASS}], photons=100_000, radius=r, camera=camera,
                     size=(64, 8))
    profile = render(scene, threads=2).pixels[..., 0].mean(axis=0)
    x = ((np.arange(64) + 0.5) / 64 - 0.5) * 1.0  # the image is 1 unit wide
    inside, outside = profile[x < -r], profile[x > r]
    assert inside.mean() == pytest.approx(t, rel=0.02)
    np.testing.assert_allclose(outside, 1.0, atol=0.01)
    # across the edge too: nothing above the lit floor, nothing below the slab's shadow
    # beyond the noise of the inside columns (a few per cent)
    assert profile.max() <= 1.01
    assert profile.min() >= t - 0.04
    assert np.all(np.diff(profile[np.abs(x) <= 2 * r]) >= -0.04)  # a step up, no dip


def test_first_caustics_compile_reports_progress(monkeypatch):
    # the caustics stage (photon map + the render kernel's kind with caustics) compiles the
    # first time; while it does, compile_progress() says how far along and compile_label()
    # what, as for the render kernels' cold compile; loaded from the cache it stays None
    import numba

    import whitted.compile.photon_map as photon_map
    from whitted.render import warm_up

    seen = []
    real = photon_map.photon_lights

    def compiling_photon_lights(*args, **kwargs):
        seen.append((warm_up.compile_progress(), warm_up.compile_label()))

        @numba.njit(cache=False)
        def fresh(x):  # a kernel never compiled before: a cold compile of the stage
            return x + 1

        fresh(1)
        seen.append((warm_up.compile_progress(), warm_up.compile_label()))
        return real(*args, **kwargs)

    monkeypatch.setattr(photon_map, "photon_lights", compiling_photon_lights)
    scene = scene_of([{"type": "sphere", "center": [0, 2, 0], "radius": 1.0,
                       "material": GLASS}], photons=2000, size=(4, 4))
    render(scene, threads=1)
    (before, _), (during, label) = seen
    assert before is None  # nothing compiled yet: no bar claims a compile
    assert 0.0 < during < 1.0 and label == "the caustics kernels"
    assert warm_up.compile_progress() is None and warm_up.compile_label() == "the kernels"
    # the CLI's bar shows it
    from whitted.cli.render import _show_compile

    class Bar:
        def update(self, task, **fields):
            self.fields = fields

    monkeypatch.setattr(warm_up, "compile_progress", lambda: 0.25)
    monkeypatch.setattr(warm_up, "compile_label", lambda: "the caustics kernels")
    bar = Bar()
    _show_compile(bar, 0)
    assert bar.fields == {"description": "compiling the caustics kernels (first run only)",
                          "completed": 0.25}


def test_an_infinite_transparent_plane_casts_no_caustic_and_says_so():
    # water as an infinite plane (y = 1) over the floor, a glass ball above it, a unit sun:
    # the plane cannot be aimed at. Its light passes as shadow rays pass it (times kt, the
    # colour), with caustics as without; the ball's photons cross it the same way
    from whitted.compile.photon_map import unbounded_specular_objects
    from whitted.compile.scene import compile_scene

    water = {"color": [1.0, 0.9, 0.8], "ka": 0.0, "kd": 0.0, "ks": 0.0, "kr": 0.0,
             "kt": 0.8, "ior": 1.33}
    plane = {"type": "plane", "point": [0, 1, 0], "normal": [0, 1, 0], "material": water}
    ball = {"type": "sphere", "center": [0, 3, 0], "radius": 1.0, "material": GLASS}
    camera = {"position": [0, 0.5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
              "projection": "orthographic", "ortho_height": 4.0}
    scene = scene_of([plane, ball], photons=50_000, camera=camera)
    assert unbounded_specular_objects(compile_scene(scene)) == [1]
    # seen from under the plane, with a ball of ior 1 (it bends nothing): the floor under
    # and around the ball is as lit as with no ball, E kt colour, the ball's photons and
    # its shadow photons crossing the plane alike
    clear = dict(GLASS, ior=1.0, fresnel=False)
    job = RenderJob(scene_of([plane, dict(ball, material=clear)], photons=50_000,
                             camera=camera).with_settings(threads=2))
    floor = job.run().pixels.reshape(-1, 3)
    assert any("objects[1]" in w and "unbounded" in w for w in job.stats.warnings)
    np.testing.assert_allclose(floor, np.tile([0.8, 0.72, 0.64], (len(floor), 1)), rtol=1e-3)
    plain = render(scene_of([plane], photons=0, camera=camera)).pixels.reshape(-1, 3)
    np.testing.assert_allclose(floor, plain, rtol=1e-3)
    # the ball's light crosses the plane times kt and the colour; the shadow photons too
    _, lights, stats = scene_photon_map(scene, threads=2)
    assert stats.targets == 1  # the ball alone
    power = lights.photons[:, PHOTON_POWER:PHOTON_POWER + 3].astype(np.float64)
    positive = power[power.sum(axis=1) > 0].sum(axis=0)
    negative = power[power.sum(axis=1) < 0].sum(axis=0)
    kt_colour = np.array([0.8, 0.72, 0.64])
    np.testing.assert_allclose(positive / math.pi, ball_power_on_floor(1.5) * kt_colour,
                               rtol=0.02)
    np.testing.assert_allclose(negative / math.pi, -kt_colour, rtol=0.01)


def test_fuzzed_caustics_tables_are_accepted_or_refused_in_one_line():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from whitted.scene.io import scene_from_dict

    values = st.one_of(st.integers(-10, 10**9), st.floats(allow_nan=True, allow_infinity=True),
                       st.text(max_size=5), st.booleans(), st.none(), st.lists(st.integers(),
                                                                              max_size=2))
    tables = st.dictionaries(st.sampled_from(["photons", "passes", "radius", "alpha",
                                              "other"]), values, max_size=4)

    @settings(max_examples=200, deadline=None)
    @given(tables)
    def check(table):
        try:
            made = scene_from_dict({"render": {"caustics": table}}, file="fuzz.toml")
        except SceneError as exc:  # one line naming the file and the key
            message = str(exc)
            assert "\n" not in message.strip() and message.startswith("fuzz.toml")
            assert "render.caustics" in message
            return
        c = made.render.caustics
        assert 0 <= c.photons <= 50_000_000 and 1 <= c.passes <= 4096
        assert 0 <= c.radius <= 1e6 and 0 < c.alpha <= 1 and math.isfinite(c.radius)

    check()


def test_render_through_a_clear_body_of_ior_1_equals_the_render_without_it():
    # ior 1, kt 1, no Fresnel, nothing of its own (ka = kd = ks = 0), seen straight down
    # (orthographic: pixel (i, j) shows the floor point ((j + 0.5) / 6 - 2, ..)): with
    # caustics the ball's shadow is filled by photons
    clear = dict(GLASS, ior=1.0, fresnel=False)
    camera = {"position": [0, 8, 0.0], "look_at": [0, 0, 0], "up": [0, 0, -1],
              "projection": "orthographic", "ortho_height": 4.0}
    ball = [{"type": "sphere", "center": [0, 2, 0], "radius": 1.0, "material": clear}]
    # 20,000 photons: few enough that some floor points see only a handful (an estimate
    # faded out where photons are few left those up to 1.2e-3 off; the caustic and shadow
    # photons, one estimator, cancel exactly)
    with_ball = scene_of(ball, photons=20_000, size=(24, 24), camera=camera)
    image = render(with_ball)
    a = image.pixels[..., 0]
    b = render(scene_of([], photons=0, size=(24, 24), camera=camera)).pixels[..., 0]
    assert np.all(b == 1.0)
    centres = (np.arange(24) + 0.5) / 6 - 2
    rho = np.hypot(*np.meshgrid(centres, centres))
    r = image.meta["stats"].photons.radius  # the default radius, fitted to the photons
    assert 0.1 < r < 0.3
    inside = rho < 1 - 2 * r
    assert inside.sum() > 20
    assert a[inside].mean() == pytest.approx(1.0, rel=0.01)
    assert np.all(np.abs(a[inside] - 1.0) < 0.05)
    assert np.all(a[rho > 1 + 2 * r] == 1.0)  # directly lit: exactly as without
    # and at the shadow's edge too: the ball's caustic photons and its shadow photons land
    # on the same points and cancel (shadow rays stopping at the ball left a rim there,
    # the estimate's half kernel missing inside, down to 1/2, and added outside, to 1 1/2)
    rim = np.abs(rho - 1) <= 2 * r
    assert rim.sum() > 20
    np.testing.assert_allclose(a, b, atol=1e-4)


def _ring_flux(lights, light_height, edges, angles=48):
    """Power on the floor in the rings ``edges`` (sampled every 0.005 in radius, at
    ``angles`` points round each circle: the gather discs cover the rings several times
    over, so sparse photons are all counted) as a render sees it: the point light's direct
    term, the clear bodies passed, plus the photon map's caustic and shadow estimate."""
    from meridian import direct

    step = 0.005
    rho = np.arange(edges[0] + step / 2, edges[-1], step)
    phi = (np.arange(angles)[None, :] + 0.5 + 0.37 * np.arange(len(rho))[:, None]) \
        * (2 * math.pi / angles)
    pts = np.stack([rho[:, None] * np.cos(phi), np.zeros_like(phi),
                    rho[:, None] * np.sin(phi)], axis=-1).reshape(-1, 3)
    e = irradiance(lights, pts, [0, 1, 0], shadows=True)[:, 0].reshape(len(rho), angles)
    ring = (e.mean(axis=1) + direct(rho, light_height)) * 2 * math.pi * rho * step
    return np.array([ring[(rho > a) & (rho < b)].sum() for a, b in zip(edges[:-1], edges[1:],
                                                                           strict=True)])


def test_hollow_ice_holding_water_matches_a_meridian_plane_trace():
    # the coursework's object: a ball of ice (R 1, n 1.31; a CSG difference) with a hollow
    # of radius 0.8 holding water (n 1.33, reaching a hair into the ice), 2 above the floor,
    # a point light 6 above it; default caustics settings. The reference traces rays in the
    # meridian plane with exact Fresnel (tests/meridian.py): under the ball a sharp caustic
    # (2.1 at the middle) in a wide, weak halo (0.046 at 0.22 from the axis, 2e-4 at 1.4):
    # light through the ball's outer zones, where photons are few
    from meridian import direct, floor_rings

    ice = dict(GLASS, ior=1.31)
    water = dict(GLASS, ior=1.33)
    lights = [{"type": "point", "position": [0, 6, 0], "intensity": 1.0,
               "falloff": "inverse_square"}]
    objects = [{"type": "csg", "operation": "difference", "material": ice,
                "objects": [{"type": "sphere", "center": [0, 2, 0], "radius": 1.0},
                            {"type": "sphere", "center": [0, 2, 0], "radius": 0.8}]},
               {"type": "sphere", "center": [0, 2, 0], "radius": 0.8001, "material": water}]
    scene = scene_of(objects, lights=lights, photons=100_000).with_settings(max_depth=10)
    _, arrays, stats = scene_photon_map(scene, threads=2)
    edges, traced, straight = floor_rings(6.0, 2.0, [1.0, 0.8], [1.31, 1.33], rays=100_000,
                                          edges=np.array([0.0, 0.3, 1.5]))
    area = math.pi * (edges[1:] ** 2 - edges[:-1] ** 2)
    rho = np.linspace(0, 1.5, 15001)
    lit = np.array([np.trapezoid((direct(rho, 6.0) * 2 * math.pi * rho)[(rho >= a) & (rho <= b)],
                                 rho[(rho >= a) & (rho <= b)])
                    for a, b in zip(edges[:-1], edges[1:], strict=True)])
    reference = (traced - straight) * area + lit
    got = _ring_flux(arrays, 6.0, edges)
    flux = got.sum() / reference.sum()
    halo = got[1] / reference[1]
    print(f"flux {flux:.4f} halo {halo:.4f} radius {stats.radius:.4f}")
    assert flux == pytest.approx(1.0, abs=0.04)
    assert halo == pytest.approx(1.0, abs=0.15)


def test_a_glass_csg_of_mesh_files_taking_its_material_casts_a_caustic(tmp_path):
    # a CSG difference of two cubes loaded from an OBJ file that names no material: the
    # cubes take the CSG's glass (POV-Ray's rule), so it is a photon target like any glass.
    # The file's meshes used to keep whitted's default white for a file without materials:
    # no photon passed, and caustics on rendered what caustics off did, bit for bit
    from whitted.compile.scene import compile_scene
    from whitted.kernels.layout import MAT_KT, PRIM_MATERIAL, PRIM_TYPE, SHAPE_TRIANGLE

    corners = [[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)]
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2],
             [1, 3, 7, 5]]
    obj = tmp_path / "cube.obj"
    obj.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in corners)
                   + "".join("f " + " ".join(str(i + 1) for i in q) + "\n" for q in quads))
    csg = {"type": "csg", "operation": "difference", "material": GLASS, "objects": [
        {"type": "mesh", "file": str(obj), "transform": {"scale": 0.5,
                                                          "translate": [0, 2, 0]}},
        {"type": "mesh", "file": str(obj), "transform": {"scale": 0.2,
                                                          "translate": [0, 2.5, 0]}}]}
    camera = {"position": [0, 0.5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
              "projection": "orthographic", "ortho_height": 2.0}
    scene = scene_of([csg], photons=20_000, size=(12, 12), camera=camera)
    compiled = compile_scene(scene)
    info = compiled.geometry.prim_info
    glass_row = info[info[:, PRIM_TYPE] == SHAPE_TRIANGLE, PRIM_MATERIAL]
    assert len(glass_row) == 24 and np.all(compiled.materials[glass_row, MAT_KT] == 1.0)
    _, lights, stats = scene_photon_map(scene, threads=2)
    assert stats.targets == 1
    # the sun's power through the cube's 1 x 1 top, less what its faces reflect and the
    # hole's faces send sideways: most of it
    assert 0.8 < caustic_power(lights) < 1.0
    # the floor under it, seen from below the cube: lit by photons through four faces
    # (F = 0.04 each: 0.85), where without caustics shadow rays pass the glass whole (1)
    lit = render(scene, threads=2).pixels[..., 0]
    plain = render(scene.with_settings(caustics=CausticsSettings())).pixels[..., 0]
    assert np.all(plain[4:8, 4:8] == 1.0)
    assert lit[4:8, 4:8].mean() == pytest.approx(0.87, abs=0.06)


DIGEST = """
import hashlib, sys
from whitted.compile.photon_map import scene_photon_map
from whitted.scene.scene import Scene
scene = Scene.model_validate_json(sys.stdin.read())
_, lights, stats = scene_photon_map(scene, threads=2)
print(hashlib.sha256(lights.photons.tobytes()).hexdigest(), repr(stats.radius))
"""


def _hollow_ice_scene(photons):
    ice = dict(GLASS, ior=1.31)
    water = dict(GLASS, ior=1.33, attenuation=[0.1, 0.05, 0.02])
    lights = [{"type": "point", "position": [0.5, 6, 0.3], "intensity": 1.0}]
    objects = [{"type": "csg", "operation": "difference", "material": ice,
                "objects": [{"type": "sphere", "center": [0, 2, 0], "radius": 1.0},
                            {"type": "torus", "major_radius": 0.3, "minor_radius": 0.5,
                             "transform": {"translate": [0, 2, 0]}}]},
               {"type": "sphere", "center": [0, 2, 0], "radius": 0.45, "material": water}]
    return scene_of(objects, lights=lights, photons=photons)


def test_photons_are_the_same_compiled_cold_or_loaded_from_the_cache(tmp_path):
    # the photon tracer is compiled without fast-math (kernels/strict.py): a process that
    # compiles it into an empty cache, one that loads it from the cache the tests use and
    # this one give the same photons, bit for bit, and so the same fitted radius
    import hashlib
    import os
    import subprocess
    import sys

    scene = _hollow_ice_scene(4000)
    _, lights, stats = scene_photon_map(scene, threads=2)
    here = (hashlib.sha256(lights.photons.tobytes()).hexdigest(), repr(stats.radius))
    assert len(lights.photons) > 1000
    runs = []
    for cache in (str(tmp_path / "empty"), os.environ.get("WHITTED_CACHE_DIR")):
        env = dict(os.environ)
        env.pop("WHITTED_CACHE_DIR", None)
        if cache:
            env["WHITTED_CACHE_DIR"] = cache
        run = subprocess.run([sys.executable, "-c", DIGEST], input=scene.model_dump_json(),
                             capture_output=True, text=True, env=env, timeout=1200,
                             check=True)
        runs.append(tuple(run.stdout.split()))
    assert runs[0] == runs[1] == here


def _general_caustics_scene(photons):
    """A glass ball, a glass torus and a glass CSG lens over a floor, lit by a point light and
    the sun: the general geometry's photon tracer (tori, CSG)."""
    lights = [{"type": "point", "position": [-2.0, 6.0, 1.0], "intensity": 0.6},
              {"type": "directional", "direction": [0.3, -1.0, -0.2], "intensity": 0.7}]
    objects = [{"type": "sphere", "center": [-1.2, 1.2, 0.0], "radius": 0.8, "material": GLASS},
               {"type": "torus", "major_radius": 0.7, "minor_radius": 0.25, "material": GLASS,
                "transform": {"rotate": [20, 0, 0], "translate": [0.8, 0.6, 0.8]}},
               {"type": "csg", "operation": "intersection", "material": GLASS,
                "transform": {"translate": [1.0, 1.6, -0.8]},
                "objects": [{"type": "sphere", "center": [0, 1.0, 0], "radius": 1.2},
                            {"type": "sphere", "center": [0, -1.0, 0], "radius": 1.2}]}]
    return scene_of(objects, photons=photons, lights=lights)


def test_general_photon_tracer_computes_what_its_python_source_does():
    # the tracer runs without fast-math (kernels/strict.py): every operation rounded as
    # IEEE 754 prescribes, in source order, so the compiled general tracer (tori, CSG: both
    # walks of a photon around one closest_hit, kernels/photons.py) stores the very bits
    # the same kernels store run as Python (NUMBA_DISABLE_JIT), where every float
    # operation is one IEEE double operation
    import hashlib
    import os
    import subprocess
    import sys

    scene = _general_caustics_scene(300)
    _, lights, stats = scene_photon_map(scene, threads=1)
    compiled = (hashlib.sha256(lights.photons.tobytes()).hexdigest(), repr(stats.radius))
    caustic = lights.photons[:, PHOTON_POWER] > 0
    assert caustic.sum() > 20 and (~caustic).sum() > 20  # caustic and shadow photons
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    run = subprocess.run([sys.executable, "-c", DIGEST.replace("threads=2", "threads=1")],
                         input=scene.model_dump_json(), capture_output=True, text=True,
                         env=env, timeout=600, check=True)
    assert tuple(run.stdout.split()) == compiled
