"""Tiny scenes for the kernel paths that tests/test_python_kernels.py's scenes leave out, rendered
by tests/test_cov_python_kernels.py in its own process and, in a fresh process, with the other
JIT mode (``python tests/python_kernel_scenes.py OUT.npz``): every light type and falloff,
Phong and Blinn highlights with a fractional exponent, two samples a pixel, a mirror with no
diffuse or specular term, soft-shadow bundles (listed occluders, a plane the light is clear
of, the list cap), shadow rays through more transparent surfaces than one walk keeps, through
a glass torus and through transparent mesh instances; and the depth, normal and object-id
AOVs."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TEAPOT = str(ROOT / "examples" / "models" / "teapot.obj")

GLASS = {"color": [0.9, 0.95, 1.0], "ka": 0.0, "kd": 0.05, "kt": 0.85, "ior": 1.3,
         "attenuation": 0.4}
MATTE = {"color": [0.8, 0.8, 0.75], "ka": 0.2, "kd": 0.8}


def _lights() -> dict:
    """Every light type and falloff, shading a floor, a Phong ball, a mirror, glass and a
    glass torus."""
    return {
        "render": {"width": 10, "height": 8, "max_depth": 2, "samples": 2},
        "camera": {"position": [0.0, 2.5, 6.0], "look_at": [0.0, 0.5, 0.0], "fov": 50.0},
        "lights": [
            {"type": "ambient", "intensity": 0.1},
            {"type": "directional", "direction": [-0.3, -1.0, -0.2], "intensity": 0.4},
            {"type": "point", "position": [2.0, 4.0, 3.0], "falloff": "inverse_square",
             "intensity": 8.0},
            {"type": "point", "position": [-2.0, 3.0, 2.0], "falloff": "linear",
             "intensity": 0.5},
            # six samples: a 3 x 2 grid of strata, listed occluders shared by the bundle
            {"type": "disk", "center": [0.0, 5.0, 0.5], "normal": [0.0, -1.0, 0.0],
             "radius": 1.0, "samples": 6, "intensity": 0.5},
        ],
        "objects": [
            {"type": "plane", "material": MATTE},
            # a wall behind, facing the camera: the disk light is clear of it
            {"type": "plane", "point": [0.0, 0.0, -3.0], "normal": [0.0, 0.0, 1.0],
             "material": MATTE},
            # a glass sheet through the disk light, its normal away from the light's centre
            {"type": "plane", "point": [0.6, 0.0, 0.0], "normal": [1.0, 0.0, 0.0],
             "material": {"ka": 0.0, "kd": 0.0, "kt": 0.9}},
            # an opaque ball under the disk light: an umbra where every sample is blocked
            {"type": "sphere", "center": [0.0, 3.2, 0.3], "radius": 1.0, "material": MATTE},
            {"type": "sphere", "center": [-1.3, 0.6, 0.0], "radius": 0.6,
             "material": {"color": [0.8, 0.2, 0.2], "kd": 0.6, "ks": 0.6, "shininess": 12.5,
                          "specular_model": "phong"}},
            {"type": "sphere", "center": [1.3, 0.6, 0.0], "radius": 0.6,
             "material": {"color": [1.0, 1.0, 1.0], "ka": 0.0, "kd": 0.0, "ks": 0.0,
                          "kr": 0.9}},
            {"type": "sphere", "center": [0.0, 0.45, 1.3], "radius": 0.45, "material": GLASS},
            {"type": "torus", "major_radius": 0.5, "minor_radius": 0.15,
             "transform": {"translate": [0.0, 1.6, 0.5], "rotate": [20.0, 0.0, 0.0]},
             "material": GLASS},
        ],
    }


def _glass_sheets(count: int, samples: int) -> dict:
    """A floor seen from below ``count`` glass sheets (planes) that a point light's and a disk
    light's shadow rays cross: more than one walk's 32 kept hits, and light dimmed past 1e-4."""
    # listed out of height order, so that a walk's nearer hits displace farther ones kept
    sheets = [{"type": "plane", "point": [0.0, 2.0 + 0.25 * (7 * k % count), 0.0],
               "normal": [0.0, 1.0, 0.0],
               "material": {"color": [0.9, 0.9, 1.0], "ka": 0.0, "kd": 0.0, "kt": 0.7}}
              for k in range(count)]
    return {
        "render": {"width": 4, "height": 3, "max_depth": 1},
        "camera": {"position": [0.0, 1.0, 0.0], "look_at": [0.0, 0.0, -1.2], "fov": 30.0},
        "lights": [
            {"type": "ambient", "intensity": 0.2},
            {"type": "point", "position": [0.3, 30.0, -1.0], "intensity": 1.0},
            {"type": "disk", "center": [0.0, 30.0, -1.0], "normal": [0.0, -1.0, 0.0],
             "radius": 2.0, "samples": samples, "intensity": 1.0},
        ],
        "objects": [{"type": "plane", "material": MATTE}, *sheets],
    }


def _teapots() -> dict:
    """27 teapots (27 x 2,464 triangles: past the flatten limit, so instanced), glass (some
    dark enough to stop the light) and opaque, and an opaque ball between a point light and
    the floor."""
    dark = dict(GLASS, attenuation=40.0)
    pots = []
    for k in range(27):
        x, z = (k % 9) - 4.0, (k // 9) - 1.0
        material = [{"color": [0.3, 0.6, 0.3], "kd": 0.8}, GLASS, dark][k % 3]
        pots.append({"type": "mesh", "file": TEAPOT, "material": material,
                     "transform": {"translate": [0.9 * x, 1.2, 0.9 * z],
                                   "scale": [0.6, 0.6, 0.6]}})
    return {
        "render": {"width": 10, "height": 8, "max_depth": 1, "mesh_tracer": "whitted"},
        "camera": {"position": [0.0, 2.0, 6.0], "look_at": [0.0, 0.0, 0.0], "fov": 40.0},
        "lights": [{"type": "ambient", "intensity": 0.2},
                   {"type": "point", "position": [0.2, 12.0, 0.3], "intensity": 1.0}],
        # and an opaque ball whose shadow falls on the floor in front
        "objects": [{"type": "plane", "material": MATTE},
                    {"type": "sphere", "center": [0.6, 6.0, 1.4], "radius": 0.6,
                     "material": MATTE}, *pots],
    }


def _textures() -> dict:
    """Checker, gradient (along u and v) and image textures (nearest and bilinear, repeat and
    clamp) on every shape's (u, v): box, cone, cylinder, disk, rectangle, triangle, a
    transformed sphere and a torus."""
    tiles = str(ROOT / "examples" / "textures" / "tiles.png")

    def image(wrap, filter_):
        return {"texture": {"type": "image", "file": tiles, "wrap": wrap, "filter": filter_,
                            "scale": [1.7, 1.3], "offset": [-0.2, 0.1]}}

    checker = {"texture": {"type": "checker", "checks": 3.0, "rotation": 20.0}}
    return {
        "render": {"width": 20, "height": 15, "max_depth": 1},
        "camera": {"position": [0.0, 3.0, 7.0], "look_at": [0.0, 0.6, 0.0], "fov": 55.0},
        "lights": [{"type": "ambient", "intensity": 0.3},
                   {"type": "point", "position": [2.0, 6.0, 5.0], "intensity": 0.8}],
        "objects": [
            {"type": "plane", "material": {"texture": {"type": "gradient", "axis": "v",
                                                       "scale": [0.1, 0.1]}}},
            {"type": "box", "min": [-3.2, 0.0, -0.5], "max": [-2.2, 1.0, 0.5],
             "material": image("clamp", "nearest")},
            {"type": "cone", "base": [-1.2, 0.0, 0.0], "top": [-1.2, 1.4, 0.0],
             "radius": 0.6, "material": image("repeat", "nearest")},
            {"type": "cylinder", "base": [0.0, 0.0, -1.0], "top": [0.0, 1.2, -1.0],
             "radius": 0.5, "material": image("clamp", "bilinear")},
            {"type": "disk", "center": [1.2, 0.8, 0.5], "normal": [0.0, 0.3, 1.0],
             "radius": 0.6, "material": checker},
            {"type": "rectangle", "corner": [2.0, 0.0, -1.0], "edge1": [1.2, 0.0, 0.0],
             "edge2": [0.0, 1.5, 0.0],
             "material": {"texture": {"type": "gradient", "axis": "u"}}},
            {"type": "triangle", "vertices": [[-1.0, 1.6, 1.0], [1.0, 1.6, 1.0],
                                              [0.0, 2.6, 1.0]],
             "material": image("repeat", "bilinear")},
            {"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0,
             "transform": {"translate": [1.5, 2.3, -1.5], "scale": [0.5, 0.8, 0.5]},
             "material": checker},
            {"type": "torus", "major_radius": 0.5, "minor_radius": 0.2,
             "transform": {"translate": [-2.4, 2.0, -0.5], "rotate": [70.0, 0.0, 0.0]},
             "material": checker},
        ],
    }


SCENES = {
    "textures": _textures,
    "lights": _lights,
    "glass_sheets": lambda: _glass_sheets(34, 4),  # the bundle's list: 34 <= 48 primitives
    "glass_sheets_past_the_list_cap": lambda: _glass_sheets(50, 4),
    "teapots": _teapots,
}


def render(name: str) -> np.ndarray:
    import whitted
    from whitted.scene.io import scene_from_dict

    scene = scene_from_dict(SCENES[name](), file=str(ROOT / "tests" / "scenes" / "x.toml"))
    return whitted.render(scene, threads=1).pixels


def render_all() -> dict[str, np.ndarray]:
    """Every scene's image, and the textures scene's depth, normal and object-id AOVs."""
    from whitted.render.api import render_aovs
    from whitted.scene.io import scene_from_dict

    out = {name: render(name) for name in SCENES}
    scene = scene_from_dict(_textures(), file=str(ROOT / "tests" / "scenes" / "x.toml"))
    for key, value in render_aovs(scene, threads=1).items():
        out[f"aov_{key}"] = np.asarray(value)
    return out


if __name__ == "__main__":
    np.savez(sys.argv[1], **render_all())
