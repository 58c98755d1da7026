"""Refraction: Snell's law, total internal reflection, Fresnel, slab displacement, nested media
(water inside ice) and Beer–Lambert absorption, checked against hand-computed values."""

from __future__ import annotations

import math

import numpy as np
import pytest

import whitted
from whitted.kernels.integrator import fresnel, refract


def test_snell_30_degrees_air_to_glass():
    # incidence 30 deg onto a surface with normal +y: sin(theta_t) = sin 30 / 1.5 = 1/3
    d = (math.sin(math.radians(30)), -math.cos(math.radians(30)), 0.0)
    ok, t = refract(d, (0.0, 1.0, 0.0), 1.0 / 1.5)
    assert ok
    assert t[0] == pytest.approx(1.0 / 3.0, abs=1e-12)
    assert t[1] == pytest.approx(-math.sqrt(1 - 1 / 9), abs=1e-12)
    assert math.hypot(*t) == pytest.approx(1.0, abs=1e-12)


def test_normal_incidence_goes_straight():
    ok, t = refract((0.0, 0.0, -1.0), (0.0, 0.0, 1.0), 1.0 / 1.333)
    assert ok and t == pytest.approx((0.0, 0.0, -1.0))


def test_total_internal_reflection_beyond_critical_angle():
    critical = math.degrees(math.asin(1 / 1.5))  # 41.81 deg from glass into air
    for angle, expect_ok in ((critical - 0.5, True), (critical + 0.5, False), (80.0, False)):
        d = (math.sin(math.radians(angle)), -math.cos(math.radians(angle)), 0.0)
        ok, _ = refract(d, (0.0, 1.0, 0.0), 1.5)
        assert ok is expect_ok


def fresnel_by_angles(theta_i, n1, n2):
    """The unpolarised Fresnel reflectance written with the angles (Born & Wolf): s and p
    as -sin(i - t) / sin(i + t) and tan(i - t) / tan(i + t); 1 past the critical angle."""
    s = n1 / n2 * math.sin(theta_i)
    if s >= 1.0:
        return 1.0
    if theta_i == 0.0:
        return ((n1 - n2) / (n1 + n2)) ** 2
    theta_t = math.asin(s)
    rs = math.sin(theta_i - theta_t) / math.sin(theta_i + theta_t)
    rp = math.tan(theta_i - theta_t) / math.tan(theta_i + theta_t)
    return 0.5 * (rs * rs + rp * rp)


def reflectance_as_traced(theta_i, n1, n2):
    """What a ray arriving at angle theta_i is reflected, as the integrator and the photons
    decide it (integrator.split_at_surface): refracted by Snell's law, then the Fresnel
    kernel; total internal reflection reflects everything."""
    d = (math.sin(theta_i), -math.cos(theta_i), 0.0)
    n = (0.0, 1.0, 0.0)
    ok, t = refract(d, n, n1 / n2)
    if not ok:
        return 1.0
    return fresnel(-(d[1] * n[1]), n1, n2, -(t[1] * n[1]))


@pytest.mark.parametrize("n1, n2", [(1.0, 1.5), (1.5, 1.0), (1.31, 1.33), (1.33, 1.31),
                                    (1.0, 1.0)])
def test_fresnel_is_exact_at_every_angle(n1, n2):
    # 0 to 90 degrees in steps of 0.05 (past the critical angle from 1.5 into 1.0: total
    # internal reflection), against the formula written with the angles
    angles = np.radians(np.linspace(0.0, 90.0, 1801))
    got = np.array([reflectance_as_traced(a, n1, n2) for a in angles])
    want = np.array([fresnel_by_angles(a, n1, n2) for a in angles[:-1]] + [1.0])
    if n1 == n2:
        want[:-1] = 0.0  # nothing to reflect: the ray goes straight on, even at grazing
        got = got[:-1]
        want = want[:-1]
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert np.all((got >= 0.0) & (got <= 1.0))


def test_fresnel_worked_values():
    # normal incidence: ((n1 - n2) / (n1 + n2))^2, the same either way through
    assert fresnel(1.0, 1.0, 1.5, 1.0) == pytest.approx(0.04, abs=1e-15)
    assert fresnel(1.0, 1.5, 1.0, 1.0) == pytest.approx(0.04, abs=1e-15)
    assert fresnel(0.0, 1.0, 1.5, math.sqrt(1 - 1 / 2.25)) == 1.0  # grazing
    # Brewster's angle, tan i = n2 / n1: the p-polarised half is not reflected at all
    i = math.atan(1.5)
    t = math.asin(math.sin(i) / 1.5)
    rs = math.sin(i - t) / math.sin(i + t)
    assert fresnel(math.cos(i), 1.0, 1.5, math.cos(t)) == pytest.approx(0.5 * rs * rs, rel=1e-12)
    # ice against water reflects almost nothing until near grazing: 5.7e-5 at normal
    # incidence, 5.2e-4 at 60 degrees, 2.8 % at 80 (Schlick's (1 - cos)^5 gave 3.1 % and 39 %)
    assert fresnel(1.0, 1.31, 1.33, 1.0) == pytest.approx((0.02 / 2.64) ** 2)
    assert reflectance_as_traced(math.radians(60.0), 1.31, 1.33) == pytest.approx(5.168e-4,
                                                                                  rel=1e-3)
    assert reflectance_as_traced(math.radians(80.0), 1.31, 1.33) == pytest.approx(0.02783,
                                                                                  rel=1e-3)


# --- end to end: an orthographic camera looks through slabs at a small bright target --------

PIXEL = 0.01  # world units per pixel
TARGET = (0.0, 0.0, -3.0)


def _glass(ior: float, attenuation: float = 0.0) -> whitted.Material:
    return whitted.Material(color=(1, 1, 1), ka=0, kd=0, ks=0, kr=0, kt=1, ior=ior,
                            attenuation=attenuation, fresnel=False)


def _target_scene(slabs: list[whitted.Box], theta_deg: float, samples: int = 9) -> whitted.Scene:
    th = math.radians(theta_deg)
    direction = np.array([math.sin(th), 0.0, -math.cos(th)])
    position = np.array(TARGET) - 10.0 * direction
    bright = whitted.Material(color=(1, 1, 1), ka=1, kd=0, ks=0)
    return whitted.Scene(
        render=whitted.RenderSettings(width=401, height=61, samples=samples, max_depth=12,
                                      min_weight=0.0),
        camera=whitted.Camera(position=tuple(position), look_at=TARGET,
                              projection="orthographic", ortho_height=61 * PIXEL),
        lights=[whitted.AmbientLight(intensity=1.0)],
        objects=[whitted.Sphere(center=TARGET, radius=0.1, material=bright), *slabs],
    )


def _centroid_x(scene: whitted.Scene) -> tuple[float, float]:
    img = whitted.render(scene).pixels[..., 1]
    cols = np.arange(img.shape[1])
    weight = img.sum(axis=0)
    centre = (cols * weight).sum() / weight.sum()
    return (centre - (img.shape[1] - 1) / 2) * PIXEL, float(img.max())


def _parallel_shift(theta: float, layers: list[tuple[float, float]]) -> float:
    """Perpendicular displacement of a ray crossing parallel layers (thickness, ior) at
    incidence theta (radians): n·sin is conserved across parallel interfaces."""
    along = sum(t * (math.tan(theta) - math.tan(math.asin(math.sin(theta) / n)))
                for t, n in layers)
    return along * math.cos(theta)


def test_glass_slab_shifts_the_ray_by_the_analytic_offset():
    theta = 30.0
    slab = whitted.Box(min=(-5, -5, -0.5), max=(5, 5, 0.5), material=_glass(1.5))
    base, _ = _centroid_x(_target_scene([], theta))
    shifted, _ = _centroid_x(_target_scene([slab], theta))
    # d = t sin(theta - theta_t) / cos(theta_t) = sin(10.529°) / cos(19.471°) = 0.19381
    expected = _parallel_shift(math.radians(theta), [(1.0, 1.5)])
    assert expected == pytest.approx(0.19381, abs=1e-5)
    assert abs(base) < 0.2 * PIXEL
    assert abs(shifted - base) == pytest.approx(expected, abs=0.3 * PIXEL)


def test_water_inside_ice_uses_the_ratio_of_their_indices():
    """Ice slab (n = 1.309, 2 thick) holding a water slab (n = 1.333, 1 thick): the ray bends at
    the ice/water interfaces by n_ice/n_water, not by 1/n_water."""
    theta = 40.0
    ice = whitted.Box(min=(-5, -5, -1), max=(5, 5, 1), material=_glass(1.309))
    water = whitted.Box(min=(-4, -4, -0.5), max=(4, 4, 0.5), material=_glass(1.333))
    base, _ = _centroid_x(_target_scene([], theta))
    shifted, _ = _centroid_x(_target_scene([ice, water], theta))
    th = math.radians(theta)
    right = _parallel_shift(th, [(1.0, 1.309), (1.0, 1.333)])
    # a renderer that forgets the ice around the water bends at the ice/water interface with
    # eta = 1/1.333 instead of 1.309/1.333: inside the water tan(theta) differs by ~0.154
    sin_ice = math.sin(th) / 1.309
    tan_right = math.tan(math.asin(sin_ice * 1.309 / 1.333))
    tan_wrong = math.tan(math.asin(sin_ice / 1.333))
    assert (tan_right - tan_wrong) * math.cos(th) > 10 * PIXEL  # the test can tell them apart
    assert abs(shifted - base) == pytest.approx(right, abs=0.3 * PIXEL)


def test_beer_lambert_absorption_along_the_path():
    # normal incidence through 2 units with attenuation 0.5: exp(-1)
    slab = whitted.Box(min=(-5, -5, -1), max=(5, 5, 1), material=_glass(1.5, attenuation=0.5))
    scene = _target_scene([slab], 0.0, samples=1)
    value = whitted.render(scene).pixels[30, 200]
    assert value == pytest.approx([math.exp(-1.0)] * 3, rel=1e-6)


def test_nested_absorption_adds_per_segment():
    # ice 0.5 thick on each side (attenuation 0.2), water 1 thick inside (attenuation 1.0)
    ice = whitted.Box(min=(-5, -5, -1), max=(5, 5, 1), material=_glass(1.309, 0.2))
    water = whitted.Box(min=(-4, -4, -0.5), max=(4, 4, 0.5), material=_glass(1.333, 1.0))
    scene = _target_scene([ice, water], 0.0, samples=1)
    value = whitted.render(scene).pixels[30, 200]
    assert value == pytest.approx([math.exp(-(0.2 * 1.0 + 1.0 * 1.0))] * 3, rel=1e-6)


def test_coloured_absorption_tints_shadows():
    """A point light shining through an absorbing cube onto a white floor: the shadow is tinted
    by exp(-attenuation * path) per channel."""
    atten = (0.1, 0.5, 1.0)
    cube = whitted.Box(min=(-1, 1, -1), max=(1, 2, 1),
                       material=whitted.Material(color=(1, 1, 1), ka=0, kd=0, ks=0, kt=1.0, ior=1.0,
                                                 attenuation=atten))
    floor = whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0),
                          material=whitted.Material(color=(1, 1, 1), ka=0, kd=1, ks=0))
    scene = whitted.Scene(
        render=whitted.RenderSettings(width=1, height=1, max_depth=0),
        camera=whitted.Camera(position=(0.0, 0.5, 0.001), look_at=(0.0, 0.0, 0.0), fov=0.1),
        lights=[whitted.PointLight(position=(0, 10, 0))],
        objects=[cube, floor],
    )
    value = whitted.render(scene).pixels[0, 0]
    hit = np.array([0.0, 0.0, 0.0])  # the pixel sees the floor straight below the camera
    expected = np.exp(-np.array(atten) * 1.0)  # 1 unit of cube on the vertical light path
    n_dot_l = (np.array([0, 10, 0]) - hit)[1] / 10.0
    assert value == pytest.approx(expected * n_dot_l, rel=2e-3)


def test_shadow_through_more_sheets_than_one_gather_holds():
    """40 stacked transparent sheets (more than a shadow walk gathers at once) between a floor
    and a light each pass kt of the light: the floor receives kt**40 of it."""
    kt = 0.9
    sheet = whitted.Material(color=(1, 1, 1), ka=0, kd=0, ks=0, kt=kt)
    sheets = [whitted.Rectangle(corner=(-5, 1 + 0.1 * k, 5), edge1=(10, 0, 0), edge2=(0, 0, -10),
                                material=sheet) for k in range(40)]
    floor = whitted.Plane(point=(0, 0, 0), normal=(0, 1, 0),
                          material=whitted.Material(color=(1, 1, 1), ka=0, kd=1, ks=0))
    scene = whitted.Scene(
        render=whitted.RenderSettings(width=1, height=1, max_depth=0),
        camera=whitted.Camera(position=(0.0, 0.5, 0.001), look_at=(0.0, 0.0, 0.0), fov=0.1),
        lights=[whitted.PointLight(position=(0, 10, 0))],
        objects=[floor, *sheets],
    )
    value = whitted.render(scene).pixels[0, 0]
    assert value == pytest.approx([kt**40] * 3, rel=1e-3)


# --- a surface between two named media: Mesh(outside=...) ---------------------------------

ICE_N, WATER_N = 1.31, 1.333


def _box_mesh(lo, hi, **fields) -> whitted.Mesh:
    """A closed box as a triangle mesh, faces counter-clockwise seen from outside."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], float)
    f = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                  [2, 3, 7], [2, 7, 6], [1, 2, 6], [1, 6, 5], [0, 4, 7], [0, 7, 3]])
    return whitted.Mesh(v, f, **fields)


def _with_named_ice(scene: whitted.Scene) -> whitted.Scene:
    return scene.model_copy(update={"materials": {"ice": _glass(ICE_N)}})


def test_refraction_from_water_into_ice_is_total_beyond_79_degrees():
    critical = math.degrees(math.asin(ICE_N / WATER_N))  # 79.34 deg
    assert critical == pytest.approx(79.34, abs=0.01)
    for angle, expect_ok in ((critical - 0.3, True), (critical + 0.3, False)):
        d = (math.sin(math.radians(angle)), -math.cos(math.radians(angle)), 0.0)
        ok, _ = refract(d, (0.0, 1.0, 0.0), WATER_N / ICE_N)
        assert ok is expect_ok


def test_water_cavity_mesh_in_ice_bends_by_their_ratio_both_ways():
    """An ice slab holding a water cavity whose one surface names ice outside: ice -> water
    and water -> ice each bend once by n_ice/n_water, the shift is the layered slabs'."""
    theta = 40.0
    ice = whitted.Box(min=(-5, -5, -1), max=(5, 5, 1), material="ice")
    water = _box_mesh((-4, -4, -0.5), (4, 4, 0.5), material=_glass(WATER_N), outside="ice")
    base, _ = _centroid_x(_target_scene([], theta))
    shifted, _ = _centroid_x(_with_named_ice(_target_scene([ice, water], theta)))
    right = _parallel_shift(math.radians(theta), [(1.0, ICE_N), (1.0, WATER_N)])
    assert abs(shifted - base) == pytest.approx(right, abs=0.3 * PIXEL)


def test_the_named_outside_medium_is_the_one_left_and_entered():
    """A water box that declares ice around it bends by n_ice/n_water where it is entered and
    left, whatever the ray came through (here air): the ray comes out parallel, shifted by
    tan(theta) - tan(theta_w) with sin(theta_w) = sin(theta) n_ice / n_water, far less than
    air -> water would shift it."""
    theta = 50.0
    th = math.radians(theta)
    water = _box_mesh((-5, -5, -0.5), (5, 5, 0.5), material=_glass(WATER_N), outside="ice")
    base, _ = _centroid_x(_target_scene([], theta))
    shifted, _ = _centroid_x(_with_named_ice(_target_scene([water], theta)))
    inside = math.asin(math.sin(th) * ICE_N / WATER_N)
    declared = (math.tan(th) - math.tan(inside)) * math.cos(th)
    from_air = _parallel_shift(th, [(1.0, WATER_N)])
    assert from_air - declared > 20 * PIXEL  # the two rules are far apart
    assert abs(shifted - base) == pytest.approx(declared, abs=0.3 * PIXEL)


def test_named_outside_is_the_same_for_flattened_and_instanced_meshes():
    from whitted.compile.scene import compile_scene

    ice = whitted.Box(min=(-5, -5, -1), max=(5, 5, 1), material="ice")
    water = _box_mesh((-4, -4, -0.5), (4, 4, 0.5), material=_glass(WATER_N), outside="ice")
    scene = _with_named_ice(_target_scene([ice, water], 35.0, samples=1))
    flat = whitted.render(scene).pixels
    job = whitted.RenderJob(scene, compiled=compile_scene(scene, flatten_limit=0))
    job.start()
    instanced = job.wait().pixels
    assert flat.max() > 0.5 and np.array_equal(flat, instanced)
