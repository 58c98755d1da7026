"""A scene as POV-Ray 3.7 scene description language (SDL).

Used to render the same scene with POV-Ray, for its own sake and to compare like with like
in ``whitted bench --compare povray``.

Axes: whitted is right-handed with +y up and the default camera looking down −z; POV-Ray is
left-handed with +y up and its default camera looking down +z. Mirroring z, (x, y, z) →
(x, y, −z), turns one into the other: every point, direction and normal is written mirrored,
and an object's transform M becomes F·M·F with F = diag(1, 1, −1). The camera's right, up
and forward vectors mirrored are exactly POV-Ray's default left-handed frame, so the image
comes out the same way round.

How the Whitted model maps onto POV-Ray's (see docs/scene-format.md for ours):

- ambient lights → ``global_settings { ambient_light }``; ``ka``·Ca/Cd → ``finish { ambient }``
  (POV-Ray multiplies it by the pigment, i.e. Cd);
- point light → ``light_source``; directional → ``parallel`` light far up-stream; disk →
  ``area_light`` with ``circular`` over the disk's own plane (a fixed disk, as ours, rather
  than ``orient``, which would turn it to face every shaded point), n×n ≈ samples, ``jitter``,
  ``area_illumination on`` (each sample shades the point from its own direction, as ours do;
  without it POV-Ray shades from the disk's centre and samples only the shadow);
- falloff ``linear`` (dist_scale/d) and ``inverse_square`` (1/d²): POV-Ray fades by
  2 / (1 + (d/fade_distance)^fade_power); with a fade_distance 1e-5 of the
  light's distance to the camera and the colour scaled to match, that is ours to 1e-5;
- ``kd`` → ``diffuse``; ``ks`` with ``phong`` → ``phong``/``phong_size``, with ``blinn`` →
  ``specular``/``roughness`` = 1/shininess (POV-Ray's highlights take the light's colour:
  a non-white ``specular_color`` scales ``ks`` by its mean);
- ``kr`` → ``reflection``; with ``fresnel`` → ``reflection { kr, kr + kt fresnel on }`` and
  ``conserve_energy`` (kr + kt·F reflected, filter·(1 − kr − kt·F) transmitted);
- ``kt`` → the pigment's ``filter`` (transmitted light is tinted by the colour, as ours);
  with ``fresnel`` and caustics, POV-Ray's ``conserve_energy`` multiplies the filter by
  1 − reflection for camera rays and photons alike (its shadow rays stop at photon
  targets), so the filter is :func:`pov_filter` (1 when kr + kt = 1: the glass preset
  transmits kt·(1 − F) in both, where a filter of kt passes kt·(kt − kt·F), 5 % less a
  surface). Without caustics the filter stays kt, which POV-Ray's shadow rays pass as
  whitted's do;
  ``ior`` and ``attenuation`` → ``interior { ior fade_power 1001 }``: POV-Ray's exponential
  fade exp(−(1 − fade_color)·d / fade_distance) equals exp(−attenuation·d) per channel;
- ``max_depth`` → ``max_trace_level`` = max_depth + 1 (POV-Ray counts the camera ray);
  ``min_weight`` → ``adc_bailout``;
- thin sheets (planes, rectangles, disks, triangles, open cylinders and cones, meshes that
  are not ``solid``) get no interior, so they bend no light; solid meshes get an
  ``inside_vector``.
"""

from __future__ import annotations

import math
import os
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..scene.camera import Camera
from ..scene.lights import AmbientLight, DirectionalLight, DiskLight, PointLight
from ..scene.materials import Material
from ..scene.scene import Scene
from ..scene.shapes import (
    CSG,
    Box,
    Cone,
    Cylinder,
    Disk,
    Mesh,
    Plane,
    Rectangle,
    Sphere,
    Torus,
    Triangle,
)
from ..scene.textures import CheckerTexture, GradientTexture, ImageTexture

MIRROR = np.diag([1.0, 1.0, -1.0])
FADE_FRACTION = 1e-5  # POV-Ray fade_distance as a fraction of the light's distance
PARALLEL_DISTANCE = 1e6  # how far up-stream a directional light is placed
IMAGE_TYPES = {".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg", ".tga": "tga", ".bmp": "bmp",
               ".gif": "gif", ".tif": "tiff", ".tiff": "tiff", ".ppm": "ppm", ".hdr": "hdr",
               ".exr": "exr"}


#: the largest photon ``count`` POV-Ray reads (a C int; a larger one wraps round)
POV_MAX_COUNT = 2**31 - 1


def pov_filter(mat: Material) -> float:
    """The pigment's ``filter`` that makes POV-Ray transmit what whitted does. Without
    ``fresnel`` it is ``kt``. With it, POV-Ray's ``conserve_energy`` passes
    filter·(1 − kr − kt·F) where whitted passes kt·(1 − F): equal at every angle for
    filter = 1 when kr + kt = 1 (the glass and water presets; ice is 0.93), and
    otherwise matched at normal incidence (F = ((n − 1)/(n + 1))²), at most 1."""
    if not mat.fresnel or mat.kt == 0.0:
        return mat.kt
    f0 = ((mat.ior - 1.0) / (mat.ior + 1.0)) ** 2
    rest = 1.0 - mat.kr - mat.kt * f0
    if rest <= 0.0:
        return mat.kt
    return min(1.0, mat.kt * (1.0 - f0) / rest)


def num(x: float) -> str:
    """A number as SDL text: shortest form that round-trips to ~10 significant digits."""
    text = format(float(x), ".10g")
    return "0" if text == "-0" else text


def vec(v) -> str:
    return "<" + ", ".join(num(c) for c in v) + ">"


def mirrored(v) -> str:
    """A point, direction or normal in POV-Ray's left-handed axes."""
    x, y, z = (float(c) for c in v)
    return vec((x, y, -z))


def matrix_keyword(m: np.ndarray) -> str:
    """``matrix <...>`` for the 4x4 column-vector matrix ``m`` given in whitted's axes."""
    a = np.eye(4)
    a[:3, :3] = MIRROR
    p = a @ m @ a
    # POV-Ray multiplies row vectors: its rows are the images of the unit axes (our columns)
    values = [p[row, col] for col in range(3) for row in range(3)] + list(p[:3, 3])
    return "matrix <" + ", ".join(num(v) for v in values) + ">"


def _colour(rgb, transmit: float = 0.0) -> str:
    if transmit > 0.0:
        return f"rgbf <{num(rgb[0])}, {num(rgb[1])}, {num(rgb[2])}, {num(transmit)}>"
    return f"rgb {vec(rgb)}"


def _perpendicular_basis(normal) -> tuple[np.ndarray, np.ndarray]:
    n = np.asarray(normal, dtype=np.float64)
    n = n / np.linalg.norm(n)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


@dataclass
class MeshParts:
    """The arrays of one mesh object, in its own coordinates."""

    vertices: np.ndarray  # (V, 3)
    faces: np.ndarray  # (T, 3)
    normals: np.ndarray | None  # (V, 3)
    uvs: np.ndarray | None  # (V, 2)
    face_material: np.ndarray | None  # (T,) index into materials
    materials: list[Material]


def mesh_parts(scene: Scene, obj: Mesh) -> MeshParts:
    """Vertices, faces and the rest of a mesh object, from its arrays or its model file."""
    if obj.file is None:
        return MeshParts(
            np.asarray(obj.vertices, dtype=np.float64), np.asarray(obj.faces, dtype=np.int64),
            None if obj.normals is None else np.asarray(obj.normals, dtype=np.float64),
            None if obj.uvs is None else np.asarray(obj.uvs, dtype=np.float64), None, [],
        )
    from ..assets import load_mesh  # the model loader (OBJ with MTL, PLY, ...)

    data = load_mesh(scene.resolve_path(obj.file))
    materials = list(getattr(data, "materials", None) or [])
    face_material = getattr(data, "face_material", None)
    return MeshParts(
        np.asarray(data.vertices, dtype=np.float64), np.asarray(data.faces, dtype=np.int64),
        None if data.normals is None else np.asarray(data.normals, dtype=np.float64),
        None if data.uvs is None else np.asarray(data.uvs, dtype=np.float64),
        None if face_material is None or not materials else np.asarray(face_material),
        materials,
    )


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted average of the face normals around each vertex."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    face_n = np.cross(b - a, c - a)
    normals = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(normals, faces[:, k], face_n)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)


def _vector_block(rows: np.ndarray, mirror: bool) -> str:
    if mirror:
        rows = rows * np.array([1.0, 1.0, -1.0])
    if rows.shape[1] == 2:
        return ",\n".join(f"<{u:.9g},{v:.9g}>" for u, v in rows.tolist())
    return ",\n".join(f"<{x:.9g},{y:.9g},{z:.9g}>" for x, y, z in rows.tolist())


class _PovWriter:
    def __init__(self, scene: Scene, width: int, height: int) -> None:
        self.scene = scene
        self.width = width
        self.height = height
        self.declarations: list[str] = []
        self.textures: dict[tuple[str, bool], str] = {}
        self.interiors: dict[str, str] = {}

    # -- materials -----------------------------------------------------------------------
    def texture_name(self, mat: Material, uv: bool) -> str:
        key = (mat.model_dump_json(), uv)
        if key not in self.textures:
            name = f"WhittedTexture{len(self.textures) + 1}"
            self.declarations.append(f"#declare {name} = texture {{\n"
                                     f"  {self.pigment(mat, uv)}\n  {self.finish(mat)}\n}}")
            self.textures[key] = name
        return self.textures[key]

    def interior_name(self, mat: Material) -> str | None:
        """A declared interior for a solid of this material, or None when it needs none."""
        atten = mat.attenuation_rgb()
        if mat.kt == 0.0 and max(atten) == 0.0 and mat.ior == 1.0:
            return None
        key = mat.model_dump_json()
        if key not in self.interiors:
            name = f"WhittedInterior{len(self.interiors) + 1}"
            body = [f"ior {num(mat.ior)}"]
            strongest = max(atten)
            if strongest > 0.0:
                fade = [1.0 - a / strongest for a in atten]
                body.append(f"fade_distance {num(1.0 / strongest)} fade_power 1001 "
                            f"fade_color {vec(fade)}")
            self.declarations.append(f"#declare {name} = interior {{ {' '.join(body)} }}")
            self.interiors[key] = name
        return self.interiors[key]

    def pigment(self, mat: Material, uv: bool) -> str:
        cd = np.asarray(mat.color)
        kt = pov_filter(mat) if self.scene.render.caustics.photons > 0 else mat.kt
        tex = mat.texture
        if tex is None:
            return f"pigment {{ {_colour(cd, kt)} }}"
        mapping = "uv_mapping " if uv else ""
        if isinstance(tex, CheckerTexture):
            # POV-Ray's checker is three-dimensional: the surface (pattern z = 0) is moved to
            # the middle of a layer of cubes, not onto the boundary between two, where
            # rounding picked the colour point by point
            body = (f"checker {_colour(cd * np.asarray(tex.color1), kt)}, "
                    f"{_colour(cd * np.asarray(tex.color2), kt)} translate <0, 0, -0.5> "
                    f"scale {num(1.0 / tex.checks)}")
        elif isinstance(tex, GradientTexture):
            body = (f"gradient {'x' if tex.axis == 'u' else 'y'} color_map {{ "
                    f"[0 {_colour(cd * np.asarray(tex.color1), kt)}] "
                    f"[1 {_colour(cd * np.asarray(tex.color2), kt)}] }}")
        else:
            assert isinstance(tex, ImageTexture)
            path = self.scene.resolve_path(tex.file)
            kind = IMAGE_TYPES.get(path.suffix.lower(), "png")
            options = [f'{kind} "{_sdl_string(path)}"']
            if tex.colorspace == "linear":
                options.append("gamma 1.0")
            if tex.filter == "bilinear":
                options.append("interpolate 2")
            if tex.wrap == "clamp":
                options.append("once")
            if kt > 0.0:
                options.append(f"filter all {num(kt)}")
            body = f"image_map {{ {' '.join(options)} }}"
            # POV-Ray cannot multiply an image by a colour: a non-white color is left out
        # ours looks up A(uv) = R·(uv·scale) + offset; POV-Ray looks up T⁻¹(p): T = A⁻¹
        sx, sy = tex.scale
        placement = (f" translate {vec((-tex.offset[0], -tex.offset[1], 0.0))}"
                     f" rotate {vec((0.0, 0.0, -tex.rotation))}"
                     f" scale {vec((1.0 / sx, 1.0 / sy, 1.0))}")
        return f"pigment {{ {mapping}{body}{placement} }}"

    def finish(self, mat: Material) -> str:
        cd = np.asarray(mat.color)
        ca = np.asarray(mat.ambient_color if mat.ambient_color is not None else mat.color)
        parts = []
        if np.allclose(ca, cd):
            parts.append(f"ambient {num(mat.ka)}")
        else:  # POV-Ray multiplies ambient by the pigment (Cd): pass ka·Ca/Cd
            ratio = np.divide(ca, cd, out=np.zeros(3), where=cd > 0)
            parts.append(f"ambient rgb {vec(mat.ka * ratio)}")
        parts.append(f"diffuse {num(mat.kd)}")
        if mat.ks > 0.0:
            ks = mat.ks * float(np.mean(mat.specular_color or (1.0, 1.0, 1.0)))
            if mat.specular_model == "phong":
                parts.append(f"phong {num(ks)} phong_size {num(mat.shininess)}")
            else:
                parts.append(f"specular {num(ks)} roughness {num(1.0 / max(mat.shininess, 1e-3))}")
        if mat.fresnel and mat.kt > 0.0:
            parts.append(f"reflection {{ {num(mat.kr)}, {num(min(1.0, mat.kr + mat.kt))} "
                         f"fresnel on }} conserve_energy")
        elif mat.kr > 0.0:
            parts.append(f"reflection {{ {num(mat.kr)} }}")
        return "finish { " + " ".join(parts) + " }"

    # -- scene parts ---------------------------------------------------------------------
    def global_settings(self) -> str:
        ambient = np.zeros(3)
        for light in self.scene.lights:
            if isinstance(light, AmbientLight):
                ambient += np.asarray(light.color) * light.intensity
        r = self.scene.render
        return ("global_settings {\n  assumed_gamma 1.0\n"
                f"  ambient_light rgb {vec(ambient)}\n"
                f"  max_trace_level {r.max_depth + 1}\n"
                f"  adc_bailout {num(r.min_weight)}\n{self.photon_settings()}}}")

    # -- caustics (docs/caustics.md): POV-Ray's photon map ---------------------------------
    def photon_settings(self) -> str:
        """``global_settings``' photons block of a scene with caustics: as many photons as
        whitted shoots in all its passes, gathered from at least 20 (POV-Ray's default)."""
        c = self.scene.render.caustics
        if c.photons == 0:
            return ""
        radius = f" radius {num(c.radius)}" if c.radius > 0 else ""
        count = c.photons * c.passes
        note = ""
        if count > POV_MAX_COUNT:  # POV-Ray keeps the count in a C int: more wraps round
            note = (f"  // whitted shoots {count} photons ({c.photons} x {c.passes} passes); "
                    f"POV-Ray's count holds at most {POV_MAX_COUNT}\n")
            count = POV_MAX_COUNT
        return (f"{note}  photons {{ count {count} autostop 0 jitter 0.4 "
                f"max_trace_level {self.scene.render.max_depth + 1} gather 20, 100"
                f"{radius} }}\n")

    def photons(self, mat: Material) -> str | None:
        """An object's photons block: bodies that reflect or refract are targets (whitted
        aims its photons at every one) and collect none."""
        if self.scene.render.caustics.photons == 0 or (mat.kr == 0.0 and mat.kt == 0.0):
            return None
        return ("photons { target reflection " + ("on" if mat.kr > 0 or mat.fresnel else "off")
                + " refraction " + ("on" if mat.kt > 0 else "off") + " collect off }")

    def camera(self) -> str:
        cam: Camera = self.scene.camera
        right, up, forward = cam.basis()
        hw, hh = cam.half_extents(self.width, self.height)
        kind = "orthographic" if cam.projection == "orthographic" else "perspective"
        blur = ""
        if cam.aperture > 0:
            # POV-Ray moves the eye by up to aperture/4 (aperture·0.5 times sample offsets
            # within ±0.5, tracepixel.cpp JitterCameraRay): twice ours reaches our lens's
            # rim. Its samples lie on a hexagonal grid, stopping early when they agree
            # (variance 0: never)
            focus = np.asarray(cam.position) + np.asarray(forward) * cam.focus()
            samples = max(19, self.scene.render.samples)
            blur = (f"  aperture {num(2 * cam.aperture)}\n  blur_samples {samples}\n"
                    f"  focal_point {mirrored(focus)}\n  variance 0\n")
        return (f"camera {{\n  {kind}\n  location {mirrored(cam.position)}\n"
                f"  direction {mirrored(forward)}\n"
                f"  right {mirrored(np.asarray(right) * 2 * hw)}\n"
                f"  up {mirrored(np.asarray(up) * 2 * hh)}\n{blur}}}")

    def background(self) -> str:
        bg = self.scene.background
        if bg.gradient is None:
            return f"background {{ {_colour(bg.color)} }}"
        # ours blends by t = (d.y + 1)/2; gradient y scaled 2 and moved down 1 gives that t
        return ("sky_sphere { pigment { gradient y color_map { "
                f"[0 {_colour(bg.gradient.bottom)}] [1 {_colour(bg.gradient.top)}] }} "
                "scale 2 translate -1*y } }")

    def light(self, light) -> str | None:
        radiance = np.asarray(light.color) * light.intensity
        if isinstance(light, AmbientLight):
            return None
        if isinstance(light, DirectionalLight):
            d = np.asarray(light.direction, dtype=np.float64)
            d /= np.linalg.norm(d)
            target = np.asarray(self.scene.camera.position)
            source = target - d * PARALLEL_DISTANCE
            return (f"light_source {{ {mirrored(source)} {_colour(radiance)} parallel "
                    f"point_at {mirrored(target)} }}")
        assert isinstance(light, PointLight | DiskLight)
        position = light.position if isinstance(light, PointLight) else light.center
        extra = []
        reach = float(np.linalg.norm(np.subtract(position, self.scene.camera.position))) or 1.0
        fade = FADE_FRACTION * reach
        if light.falloff == "linear":  # 2/(1 + d/f) ≈ 2f/d: scale by dist_scale/(2f)
            radiance = radiance * light.dist_scale / (2.0 * fade)
            extra.append(f"fade_distance {num(fade)} fade_power 1")
        elif light.falloff == "inverse_square":  # 2/(1 + (d/f)²) ≈ 2f²/d²
            radiance = radiance / (2.0 * fade * fade)
            extra.append(f"fade_distance {num(fade)} fade_power 2")
        if isinstance(light, DiskLight):
            samples = light.samples or self.scene.render.shadow_samples
            n = max(1, round(math.sqrt(samples)))
            u, v = _perpendicular_basis(light.normal)
            extra.insert(0, f"area_light {mirrored(u * 2 * light.radius)}, "
                            f"{mirrored(v * 2 * light.radius)}, {n}, {n} circular jitter "
                            "area_illumination on")
        return (f"light_source {{ {mirrored(position)} {_colour(radiance)}"
                + "".join(f"\n  {e}" for e in extra) + " }")

    def shape(self, index: int, obj) -> str:
        if isinstance(obj, Mesh):
            return self.mesh(index, obj)
        if isinstance(obj, CSG):
            return _labelled(index, obj) + self.csg(index, obj, self.scene.material_of(index))
        mat = self.scene.material_of(index)
        body, solid, uv, placement = self.primitive(index, obj)
        lines = [body, f"  texture {{ {self.texture_name(mat, uv)}{placement} }}"]
        lines += self.body_lines(mat if solid else None, mat, obj.transform)
        return _labelled(index, obj) + "\n".join(lines) + "\n}"

    def body_lines(self, medium: Material | None, photons_of: Material | None,
                   transform) -> list[str]:
        """What closes an object's block: its interior (``medium``'s, None: none), its
        photons block (``photons_of``'s, when caustics are on) and its transform."""
        lines = []
        interior = self.interior_name(medium) if medium is not None else None
        if interior is not None:
            lines.append(f"  interior {{ {interior} }}")
        if photons_of is not None and (photons := self.photons(photons_of)) is not None:
            lines.append(f"  {photons}")
        if transform is not None and not transform.is_identity():
            lines.append(f"  {matrix_keyword(transform.matrix())}")
        return lines

    def csg(self, index: int, obj: CSG, inherited: Material, top: bool = True) -> str:
        """POV-Ray's union / intersection / difference / merge of the children, each with its
        own texture (a child without a material takes the nearest CSG object's, as POV-Ray's
        children without a texture do) and one interior for the whole body: the object's
        material, or its first solid's (whitted's medium of a CSG object)."""
        children = []
        for child in obj.objects:
            mat = (self.scene.resolve_material(child.material) if child.material is not None
                   else inherited)
            if isinstance(child, CSG):
                children.append(self.csg(index, child, mat, top=False))
                continue
            if isinstance(child, Mesh):  # POV-Ray takes a closed mesh2 in CSG
                lines, _ = self.mesh2(child, mat)
                children.append("\n".join([*lines, *self.body_lines(None, None,
                                                                      child.transform)]) + "\n}")
                continue
            body, _, uv, placement = self.primitive(index, child)
            lines = [body, f"  texture {{ {self.texture_name(mat, uv)}{placement} }}",
                     *self.body_lines(None, None, child.transform)]
            children.append("\n".join(lines) + "\n}")
        lines = [f"{obj.operation} {{", *("  " + c.replace("\n", "\n  ") for c in children)]
        medium = None
        if top:
            medium = inherited if obj.material is not None else _first_material(
                self.scene, obj, inherited)
        lines += self.body_lines(medium, medium, obj.transform)
        return "\n".join(lines) + "\n}"

    def primitive(self, index: int, obj) -> tuple[str, bool, bool, str]:
        """(the opening of the shape's block, whether it bounds a volume, whether its texture
        is uv-mapped, a texture placement) for an analytic shape."""
        solid = True
        uv = isinstance(obj, Sphere | Box | Rectangle | Triangle | Mesh)
        placement = ""  # texture orientation for shapes POV-Ray has no uv mapping for
        if isinstance(obj, Sphere):
            body = f"sphere {{ {mirrored(obj.center)}, {num(obj.radius)}"
        elif isinstance(obj, Plane):
            n = np.asarray(obj.normal) / np.linalg.norm(obj.normal)
            body = f"plane {{ {mirrored(n)}, {num(float(np.dot(n, obj.point)))}"
            placement = _planar_placement(obj.normal, obj.point)
            solid = False
        elif isinstance(obj, Rectangle):
            c = np.asarray(obj.corner)
            e1, e2 = np.asarray(obj.edge1), np.asarray(obj.edge2)
            a, b, cc, d = c, c + e1, c + e1 + e2, c + e2
            body = (f"mesh {{\n  triangle {{ {mirrored(a)}, {mirrored(b)}, {mirrored(cc)} "
                    "uv_vectors <0,0>, <1,0>, <1,1> }\n"
                    f"  triangle {{ {mirrored(a)}, {mirrored(cc)}, {mirrored(d)} "
                    "uv_vectors <0,0>, <1,1>, <0,1> }")
            solid = False
        elif isinstance(obj, Disk):
            n = np.asarray(obj.normal) / np.linalg.norm(obj.normal)
            body = f"disc {{ {mirrored(obj.center)}, {mirrored(n)}, {num(obj.radius)}"
            placement = _planar_placement(obj.normal, obj.center)
            solid = False
        elif isinstance(obj, Triangle):
            a, b, c = obj.vertices
            body = (f"mesh {{\n  triangle {{ {mirrored(a)}, {mirrored(b)}, {mirrored(c)} "
                    "uv_vectors <0,0>, <1,0>, <0,1> }")
            solid = False
        elif isinstance(obj, Box):
            if obj.min is not None and obj.max is not None:
                body = f"box {{ {mirrored(obj.min)}, {mirrored(obj.max)}"
            else:
                corner, edges = obj.corner_and_edges()
                affine = np.eye(4)
                affine[:3, :3] = np.asarray(edges).T  # columns: the images of x, y, z
                affine[:3, 3] = corner
                body = f"box {{ <0, 0, 0>, <1, 1, 1> {matrix_keyword(affine)}"
        elif isinstance(obj, Cylinder):
            body = (f"cylinder {{ {mirrored(obj.base)}, {mirrored(obj.top)}, {num(obj.radius)}"
                    + ("" if obj.capped else " open"))
            solid = obj.capped
        elif isinstance(obj, Cone):
            body = (f"cone {{ {mirrored(obj.base)}, {num(obj.radius)}, {mirrored(obj.top)}, "
                    f"{num(obj.top_radius)}" + ("" if obj.capped else " open"))
            solid = obj.capped
        elif isinstance(obj, Torus):  # POV-Ray's torus lies around y too (mirroring z
            # leaves it as it is)
            body = f"torus {{ {num(obj.major_radius)}, {num(obj.minor_radius)}"
        else:  # pragma: no cover - every shape type is handled above
            raise SceneError(f"objects[{index}]: cannot export a {obj.type!r} to POV-Ray")
        return body, solid, uv, placement

    def mesh(self, index: int, obj: Mesh) -> str:
        lines, material = self.mesh2(obj, None, index)
        lines += self.body_lines(material if obj.solid else None, material, obj.transform)
        return _labelled(index, obj) + "\n".join(lines) + "\n}"

    def mesh2(self, obj: Mesh, material: Material | None,
              index: int | None = None) -> tuple[list[str], Material]:
        """The lines of a ``mesh2`` block up to its texture (the block left open), and the
        material that fills it. ``material``: one material for every triangle (a mesh in
        CSG, which whitted shades with its child's or the CSG object's material); None: the
        object's own, or the file's per triangle."""
        parts = mesh_parts(self.scene, obj)
        normals = parts.normals
        if obj.smooth is False:
            normals = None
        elif obj.smooth and normals is None:
            normals = vertex_normals(parts.vertices, parts.faces)
        n_vertices = len(parts.vertices)
        faces = parts.faces
        out = [f"mesh2 {{\n  vertex_vectors {{ {n_vertices},\n"
               f"{_vector_block(parts.vertices, True)}\n  }}"]
        if normals is not None:
            out.append(f"  normal_vectors {{ {len(normals)},\n{_vector_block(normals, True)}\n  }}")
        if parts.uvs is not None:
            block = _vector_block(parts.uvs, False)
            out.append(f"  uv_vectors {{ {len(parts.uvs)},\n{block}\n  }}")
        per_face = (material is None and obj.material is None
                    and parts.face_material is not None and len(parts.materials) > 1)
        if per_face:
            names = [self.texture_name(m, True) for m in parts.materials]
            out.append(f"  texture_list {{ {len(names)}, "
                       + ", ".join(f"texture {{ {n} }}" for n in names) + " }")
            rows = "\n".join(f"<{a},{b},{c}>,{t}," for (a, b, c), t in
                             zip(faces.tolist(), parts.face_material.tolist(), strict=True))
        else:
            rows = "\n".join(f"<{a},{b},{c}>," for a, b, c in faces.tolist())
        out.append(f"  face_indices {{ {len(faces)},\n{rows.rstrip(',')}\n  }}")
        if obj.solid:
            out.append("  inside_vector <0, 0, 1>")
        if per_face:
            candidates = [m for m in parts.materials if m.kt > 0.0] or parts.materials[:1]
            material = candidates[0]
        else:
            if material is None:
                material = (self.scene.material_of(index) if obj.material is not None or
                            not parts.materials else parts.materials[0])
            out.append(f"  texture {{ {self.texture_name(material, True)} }}")
        return out, material

    def write(self, source: str | None) -> str:
        r = self.scene.render
        body = [self.global_settings(), self.camera(), self.background()]
        body += [t for t in (self.light(light) for light in self.scene.lights) if t]
        shapes = [self.shape(i, obj) for i, obj in enumerate(self.scene.objects)]
        header = [
            WHITTED_HEADER + (f" from {source}" if source else ""),
            f"// render: povray +I<this file> +W{self.width} +H{self.height} "
            f"{povray_antialias_options(self.scene)} +FN"
            + (" File_Gamma=1.0" if r.transfer == "linear" else "")
            + (f"  (whitted's samples per pixel: {r.samples}; -A: one ray per pixel)"
               if r.antialias is None else "  (adaptive anti-aliasing, as whitted's)"),
            "#version 3.7;",
        ]
        return "\n\n".join(["\n".join(header), *body, *self.declarations, *shapes]) + "\n"


def povray_antialias_options(scene: Scene) -> str:
    """POV-Ray's anti-aliasing options for the scene: ``-A`` (one ray per pixel), or for
    ``[render.antialias]`` method 2 at its threshold and depth (``+A0.3 +AM2 +R3``)."""
    aa = scene.render.antialias
    if aa is None:
        return "-A"
    return f"+A{num(aa.threshold)} +AM2 +R{max(1, aa.levels)}"


def _first_material(scene: Scene, obj: CSG, inherited: Material) -> Material:
    """The material of a CSG object's first solid (its children's order, depth first)."""
    child = obj.objects[0]
    mat = scene.resolve_material(child.material) if child.material is not None else inherited
    return _first_material(scene, child, mat) if isinstance(child, CSG) else mat


def _labelled(index: int, obj) -> str:
    label = f"// objects[{index}] {obj.type}" + (f" '{obj.name}'" if obj.name else "")
    return label.replace("\n", " ") + "\n"


def _planar_placement(normal, point) -> str:
    """A texture transform that lays POV-Ray's x/y pattern plane onto the given plane, x
    along whitted's u direction there (compile/geometry.py ``tangent``: world x made
    perpendicular to the normal, or -z for surfaces facing along x) and y along v = n x u."""
    n = np.asarray(normal, dtype=np.float64) / np.linalg.norm(normal)
    helper = (np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9
              else np.array([0.0, 0.0, -np.sign(n[0])]))
    u = helper - np.dot(helper, n) * n
    u /= np.linalg.norm(u)
    v = np.cross(n, u)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = u, v, n
    m[:3, 3] = point
    return " " + matrix_keyword(m)


def _sdl_string(path: Path) -> str:
    return str(path).replace("\\", "/").replace('"', '\\"')


def scene_to_pov(
    scene: Scene, *, width: int | None = None, height: int | None = None,
    source: str | None = None,
) -> str:
    """The scene as POV-Ray 3.7 SDL text, for an image of ``width`` × ``height`` (default: the
    scene's render size)."""
    writer = _PovWriter(scene, width or scene.render.width, height or scene.render.height)
    return writer.write(source)


#: The first line of every file whitted exports (then `` from SOURCE``): how whitted tells
#: its own exports, which it may replace, from anyone else's files, which it never does.
WHITTED_HEADER = "// POV-Ray 3.7 scene written by whitted"


def written_by_whitted(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a file whose first line says whitted wrote it (an export)."""
    try:
        with open(path, "rb") as file:
            start = file.read(len(WHITTED_HEADER) + 1)
    except OSError:
        return False
    return start.decode("utf-8", "replace").startswith(WHITTED_HEADER)


def foreign_file(path: str | os.PathLike[str]) -> bool:
    """Whether something that whitted did not export is at ``path`` (a file of someone
    else's, which an export must not replace unless asked to). A folder, a device or a pipe
    is left to the output checks, which refuse them whatever is asked."""
    try:
        status = os.stat(path)
    except (OSError, ValueError):
        return False
    return stat.S_ISREG(status.st_mode) and not written_by_whitted(path)


def export_pov(
    scene: Scene, path: str | os.PathLike[str], *, width: int | None = None,
    height: int | None = None, source: str | None = None, force: bool = False,
) -> Path:
    """Write the scene as a POV-Ray 3.7 file at ``path`` (atomically). Returns the path.
    :class:`~whitted.errors.OutputError` when ``path`` is the scene file (``source``) or a
    file the scene reads, or cannot be written, or when a file whitted did not write is
    there (whitted's exports start with :data:`WHITTED_HEADER`): ``force=True`` replaces
    that one."""
    from ..errors import OutputError
    from ..files import atomic_write
    from ..output.safety import check_outputs

    path = Path(path)
    source_file = source if source and Path(source).suffix.lower() in (".toml", ".json") else None
    check_outputs([path], scene, source_file)
    if not force and foreign_file(path):
        raise OutputError(f"{path}: is not a file whitted exported; it is kept (force=True "
                          "replaces it)")
    text = scene_to_pov(scene, width=width, height=height, source=source)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    return path
