"""Which properties each kind of item shows and with which editor. Pure data: a list of
:class:`Spec` per item, computed from the item (a box given by min/max shows min/max, one
given by corner + edges shows those)."""

from __future__ import annotations

import types
import typing
from dataclasses import dataclass, field
from typing import Any, Literal

from ..scene import PRESETS

# editor kinds
TEXT, NUMBER, INT, OPT_INT, VEC3, ANGLES, SCALE, COLOUR, COEF, CHOICE, BOOL, FILE, ATTEN = (
    "text", "number", "int", "opt_int", "vec3", "angles", "scale", "colour", "coef", "choice",
    "bool", "file", "attenuation",
)
UV = "uv"  # two numbers u, v (texture coordinates)
# the headings the panel groups fields under
GEOMETRY, TRANSFORM, MATERIAL, TEXTURE, LIGHT, VIEW, IMAGE, QUALITY, OUTPUT, BLUR = (
    "Shape", "Placement (transform)", "Material", "Texture", "Light", "View", "Image", "Quality",
    "Output", "Focal blur",
)


@dataclass(frozen=True)
class Spec:
    """One property: where it lives in the item (``path`` of keys), its label and editor.
    ``lo``/``hi`` are the slider's range for COEF (the box takes any valid value)."""

    path: tuple
    label: str
    kind: str
    group: str = ""
    lo: float = 0.0
    hi: float = 1.0
    choices: tuple = ()
    tip: str = ""
    filters: str = field(default="", compare=False)

    @property
    def name(self) -> str:
        return ".".join(str(p) for p in self.path)


def _name() -> list[Spec]:
    return [Spec(("name",), "Name", TEXT, tip="shown in the scene tree; optional")]


def transform_specs(item: Any) -> list[Spec]:
    t = ("transform",)
    specs = [
        Spec((*t, "translate"), "Move by", VEC3, TRANSFORM, tip="translation, scene units"),
        Spec((*t, "rotate"), "Rotate (°)", ANGLES, TRANSFORM,
             tip="degrees about x, then y, then z (about the world origin)"),
        Spec((*t, "scale"), "Scale", SCALE, TRANSFORM,
             tip="one number, or x, y, z for a non-uniform scale"),
    ]
    tr = getattr(item, "transform", None)
    if tr is not None and tr.axis_angle is not None:
        specs += [
            Spec((*t, "axis_angle", "axis"), "Extra axis", VEC3, TRANSFORM),
            Spec((*t, "axis_angle", "angle"), "Extra angle (°)", NUMBER, TRANSFORM),
        ]
    return specs


TEXTURE_KINDS = ("none", "image", "checker", "gradient")
IMAGE_FILTER = "Images (*.png *.jpg *.jpeg *.bmp *.tga *.tif *.tiff *.exr *.hdr);;All files (*)"


def material_specs(material: Any) -> list[Spec]:
    m = ("material",)
    g = MATERIAL
    specs = [
        Spec((*m, "color"), "Colour", COLOUR, g, tip="diffuse colour Cd"),
        Spec((*m, "ka"), "Ambient ka", COEF, g),
        Spec((*m, "kd"), "Diffuse kd", COEF, g),
        Spec((*m, "ks"), "Specular ks", COEF, g),
        Spec((*m, "shininess"), "Shininess", COEF, g, 1.0, 1000.0,
             tip="Phong exponent, 0..100000 (the slider covers 1..1000)"),
        Spec((*m, "specular_model"), "Highlight model", CHOICE, g, choices=("blinn", "phong")),
        Spec((*m, "specular_color"), "Specular colour", COLOUR, g, tip="Cs (default white)"),
        Spec((*m, "kr"), "Reflection kr", COEF, g),
        Spec((*m, "kt"), "Transparency kt", COEF, g),
        Spec((*m, "ior"), "Refractive index", COEF, g, 1.0, 3.0, tip="ior, 0..10 (glass 1.5)"),
        Spec((*m, "attenuation"), "Attenuation", ATTEN, g, 0.0, 2.0,
             tip="absorption per unit length inside; a number or r, g, b"),
        Spec((*m, "fresnel"), "Fresnel", BOOL, g,
             tip="split kt into reflection by the Fresnel equations"),
    ]
    tex = getattr(material, "texture", None)
    if "texture" not in type(material).model_fields:
        return specs
    t = (*m, "texture")
    specs.append(Spec((*t, "type"), "Texture", CHOICE, TEXTURE, choices=TEXTURE_KINDS))
    kind = getattr(tex, "type", "none")
    if kind == "image":
        specs += [Spec((*t, "file"), "Image file", FILE, TEXTURE, filters=IMAGE_FILTER),
                  Spec((*t, "wrap"), "Wrap", CHOICE, TEXTURE, choices=("repeat", "clamp"))]
    elif kind == "checker":
        specs += [Spec((*t, "color1"), "Colour 1", COLOUR, TEXTURE),
                  Spec((*t, "color2"), "Colour 2", COLOUR, TEXTURE),
                  Spec((*t, "checks"), "Checks per unit", COEF, TEXTURE, 1.0, 64.0)]
    elif kind == "gradient":
        specs += [Spec((*t, "color1"), "Colour at 0", COLOUR, TEXTURE),
                  Spec((*t, "color2"), "Colour at 1", COLOUR, TEXTURE),
                  Spec((*t, "axis"), "Along", CHOICE, TEXTURE, choices=("u", "v"))]
    return specs


MODEL_FILTER = ("3D models (*.obj *.ply *.stl *.off *.glb *.gltf);;All files (*)")

#: every shape's fields the panel does not show in its Shape section (shown elsewhere, or
#: a CSG object's children, which are items of their own in the tree)
NOT_SHAPE_FIELDS = ("type", "name", "material", "transform", "objects")
#: labels and tips of shape fields whose name does not say it well enough
FIELD_LABELS = {"center": "Centre", "major_radius": "Major radius",
                "minor_radius": "Minor (tube) radius"}
FIELD_TIPS = {"major_radius": "from the centre to the middle of the tube, in the xz plane",
              "minor_radius": "the tube's radius",
              "operation": "difference: the first child minus the others; merge: a union "
                           "without inner surfaces"}


def _editor_kind(annotation: Any) -> tuple[str, tuple]:
    """The editor for a field of this type, and its choices (None: no editor fits)."""
    args = [a for a in typing.get_args(annotation) if a is not type(None)]
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType) and len(args) == 1:
        return _editor_kind(args[0])
    if origin is typing.Annotated:
        return _editor_kind(args[0])
    if origin is Literal:
        return CHOICE, tuple(args)
    if annotation is bool:
        return BOOL, ()
    if annotation is float:
        return NUMBER, ()
    if annotation is int:
        return INT, ()
    if origin is tuple and len(args) == 3 and all(_editor_kind(a)[0] == NUMBER for a in args):
        return VEC3, ()
    return "", ()


def shape_field_specs(obj: Any) -> list[Spec]:
    """The Shape section of a kind of object, made from its model's fields (numbers, vectors,
    choices, switches): what a shape without a hand-made section shows."""
    specs = []
    for name, info in type(obj).model_fields.items():
        if name in NOT_SHAPE_FIELDS:
            continue
        kind, choices = _editor_kind(info.annotation)
        if not kind:
            continue
        label = FIELD_LABELS.get(name, name.replace("_", " ").capitalize())
        specs.append(Spec((name,), label, kind, GEOMETRY, choices=choices,
                          tip=FIELD_TIPS.get(name, "")))
    return specs


#: shapes whose Shape section is made by hand (labels, tips, the form a box is given in);
#: every other shape's is made from its fields
HAND_MADE = ("sphere", "plane", "rectangle", "disk", "triangle", "box", "cylinder", "cone",
             "mesh")


def object_specs(obj: Any) -> list[Spec]:
    g = GEOMETRY
    kind = obj.type
    specs = _name()
    if kind not in HAND_MADE:
        specs += shape_field_specs(obj)
    elif kind == "sphere":
        specs += [Spec(("center",), "Centre", VEC3, g), Spec(("radius",), "Radius", NUMBER, g)]
    elif kind == "plane":
        specs += [Spec(("point",), "Point", VEC3, g), Spec(("normal",), "Normal", VEC3, g)]
    elif kind == "rectangle":
        specs += [Spec(("corner",), "Corner", VEC3, g, tip="Q1"),
                  Spec(("edge1",), "Edge 1", VEC3, g, tip="Q2 − Q1"),
                  Spec(("edge2",), "Edge 2", VEC3, g, tip="Q3 − Q1")]
    elif kind == "disk":
        specs += [Spec(("center",), "Centre", VEC3, g), Spec(("normal",), "Normal", VEC3, g),
                  Spec(("radius",), "Radius", NUMBER, g)]
    elif kind == "triangle":
        specs += [Spec(("vertices", i), f"Vertex {'abc'[i]}", VEC3, g) for i in range(3)]
        specs += [Spec(("uvs", i), f"UV at {'abc'[i]}", UV, g,
                       tip=f"texture coordinates of vertex {'abc'[i]}") for i in range(3)]
    elif kind == "box":
        if obj.min is not None:
            specs += [Spec(("min",), "Min corner", VEC3, g), Spec(("max",), "Max corner", VEC3, g)]
        else:
            specs += [Spec(("corner",), "Corner", VEC3, g)]
            specs += [Spec(("edges", i), f"Edge {i + 1}", VEC3, g) for i in range(3)]
    elif kind in ("cylinder", "cone"):
        specs += [Spec(("base",), "Base centre", VEC3, g), Spec(("top",), "Top centre", VEC3, g),
                  Spec(("radius",), "Radius" if kind == "cylinder" else "Base radius", NUMBER, g)]
        if kind == "cone":
            specs.append(Spec(("top_radius",), "Top radius", NUMBER, g, tip="> 0: a frustum"))
        specs.append(Spec(("capped",), "Capped", BOOL, g))
    elif kind == "mesh":
        if getattr(obj, "file", None) is not None:
            specs.append(Spec(("file",), "Model file", FILE, g, filters=MODEL_FILTER))
        specs += [Spec(("smooth",), "Smooth shading", CHOICE, g, choices=("auto", "on", "off")),
                  Spec(("crease_angle",), "Crease angle (°)", COEF, g, 0.0, 180.0),
                  Spec(("solid",), "Solid (refracts)", BOOL, g),
                  Spec(("outside",), "Outside medium", TEXT, g,
                       tip="the material just outside a solid mesh, by name; empty: the "
                           "medium the ray arrives through")]
    return specs + transform_specs(obj)


def light_specs(light: Any) -> list[Spec]:
    g = LIGHT
    specs = _name() + [
        Spec(("color",), "Colour", COLOUR, g),
        Spec(("intensity",), "Intensity", COEF, g, 0.0, 2.0, tip="0..1e9 (slider 0..2)"),
    ]
    kind = light.type
    if kind == "point":
        specs.append(Spec(("position",), "Position", VEC3, g))
    elif kind == "directional":
        specs.append(Spec(("direction",), "Direction", VEC3, g, tip="where the light travels"))
    elif kind == "disk":
        specs += [Spec(("center",), "Centre", VEC3, g), Spec(("normal",), "Normal", VEC3, g),
                  Spec(("radius",), "Radius", NUMBER, g),
                  Spec(("samples",), "Shadow samples", OPT_INT, g,
                       tip="empty: the render setting")]
    if kind in ("point", "disk"):
        specs += [Spec(("falloff",), "Falloff", CHOICE, g,
                       choices=("none", "linear", "inverse_square")),
                  Spec(("dist_scale",), "Distance scale", NUMBER, g, tip="for linear falloff")]
    return specs


def camera_specs(camera: Any) -> list[Spec]:
    g = VIEW
    specs = [Spec(("position",), "Position", VEC3, g, tip="the eye")]
    if camera.rotate is not None or camera.axis_angle is not None:
        specs.append(Spec(("rotate",), "Rotate (°)", ANGLES, g, tip="about x, then y, then z"))
    else:
        specs += [Spec(("look_at",), "Look at", VEC3, g), Spec(("up",), "Up", VEC3, g)]
    specs += [
        Spec(("fov",), "Field of view (°)", COEF, g, 5.0, 150.0, tip="0 < fov < 180"),
        Spec(("fov_axis",), "Field of view is", CHOICE, g, choices=("y", "x"),
             tip="y: vertical, x: horizontal"),
        Spec(("projection",), "Projection", CHOICE, g, choices=("perspective", "orthographic")),
    ]
    if camera.projection == "orthographic":
        specs.append(Spec(("ortho_height",), "Visible height", NUMBER, g))
    specs += [
        Spec(("aperture",), "Aperture", COEF, BLUR, 0.0, 1.0,
             tip="the lens's diameter in scene units: 0 is a pinhole (everything sharp); "
                 "larger blurs more what is not in focus (the box takes up to 1e6)"),
        Spec(("focus_mode",), "Focus on", CHOICE, BLUR, choices=FOCUS_MODES,
             tip="the plane in focus: through the point the camera looks at, at a distance "
                 "along the view, or through a point"),
    ]
    if camera.focal_distance is not None:
        specs.append(Spec(("focal_distance",), "Focal distance", NUMBER, BLUR,
                          tip="along the viewing direction, scene units"))
    elif camera.focal_point is not None:
        specs.append(Spec(("focal_point",), "Focal point", VEC3, BLUR,
                          tip="the plane through this point, facing the camera, is sharp"))
    return specs


#: the camera's "Focus on" choices: its look_at point, a distance, a point
FOCUS_MODES = ("look-at point", "distance", "point")


def focus_mode(camera: Any) -> str:
    if camera.focal_distance is not None:
        return "distance"
    return "point" if camera.focal_point is not None else "look-at point"


def render_specs(settings: Any) -> list[Spec]:
    return [
        Spec(("width",), "Width (px)", INT, IMAGE),
        Spec(("height",), "Height (px)", INT, IMAGE),
        Spec(("max_depth",), "Recursion depth", INT, QUALITY, tip="0..64"),
        Spec(("samples",), "Samples per pixel", INT, QUALITY, tip="anti-aliasing, 1..4096"),
        Spec(("shadow_samples",), "Soft-shadow samples", INT, QUALITY,
             tip="per disk light, 1..4096"),
        Spec(("min_weight",), "Min ray weight", COEF, QUALITY, 0.0, 0.1),
        Spec(("threads",), "Threads", INT, QUALITY, tip="0 = every core"),
        Spec(("seed",), "Seed", INT, QUALITY),
        Spec(("caustics", "photons"), "Caustic photons", INT, QUALITY,
             tip="photons per pass (docs/caustics.md); 0 = no caustics"),
        Spec(("caustics", "passes"), "Caustic passes", INT, QUALITY,
             tip="progressive photon-mapping passes, 1..4096"),
        Spec(("caustics", "radius"), "Caustic radius", NUMBER, QUALITY,
             tip="first pass's gather radius; 0 = chosen from the scene"),
        Spec(("transfer",), "Transfer", CHOICE, OUTPUT, choices=("srgb", "linear")),
        Spec(("tonemap",), "Tone map", CHOICE, OUTPUT, choices=("clamp", "reinhard", "aces")),
    ]


def background_specs(background: Any) -> list[Spec]:
    g = "Background"
    specs = [Spec(("mode",), "Kind", CHOICE, g, choices=("colour", "gradient"))]
    if background.gradient is None:
        specs.append(Spec(("color",), "Colour", COLOUR, g))
    else:
        specs += [Spec(("gradient", "top"), "Top", COLOUR, g),
                  Spec(("gradient", "bottom"), "Bottom", COLOUR, g)]
    return specs


PRESET_NAMES = tuple(PRESETS)
