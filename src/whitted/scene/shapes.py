"""Shapes. Every one takes a ``transform``. The analytic ones are intersected exactly (no
tessellation); a ``Mesh`` is made of triangles (from a model file or from arrays)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BeforeValidator, Field, PlainSerializer, model_validator

from ..errors import SceneError
from ..files import path_problem
from .materials import Material
from .types import MAX_MAGNITUDE, Direction, Finite, Strict, Transform, Vec3


class _Shape(Strict):
    name: str | None = None
    material: str | Material | None = None
    transform: Transform | None = None


class Sphere(_Shape):
    type: Literal["sphere"] = "sphere"
    center: Vec3 = (0.0, 0.0, 0.0)
    radius: float = Field(gt=0.0)


class Plane(_Shape):
    """An infinite plane through ``point`` with ``normal`` (both sides shade)."""

    type: Literal["plane"] = "plane"
    point: Vec3 = (0.0, 0.0, 0.0)
    normal: Direction = (0.0, 1.0, 0.0)


class Rectangle(_Shape):
    """A parallelogram: ``corner`` plus ``edge1`` and ``edge2`` (the lecture's Q1, Q2−Q1, Q3−Q1);
    points ``corner + u·edge1 + v·edge2`` with u, v in 0..1; normal ``edge1 × edge2``."""

    type: Literal["rectangle"] = "rectangle"
    corner: Vec3
    edge1: Direction
    edge2: Direction

    @model_validator(mode="after")
    def _not_degenerate(self) -> Rectangle:
        if np.linalg.norm(np.cross(self.edge1, self.edge2)) < 1e-12:
            raise ValueError("edge1 and edge2 are parallel: the rectangle has no area")
        return self


class Disk(_Shape):
    type: Literal["disk"] = "disk"
    center: Vec3 = (0.0, 0.0, 0.0)
    normal: Direction = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)


class Triangle(_Shape):
    """Three corners, front side counter-clockwise; ``uvs`` are the corners' texture
    coordinates (a texture is mapped by barycentric weight)."""

    type: Literal["triangle"] = "triangle"
    vertices: tuple[Vec3, Vec3, Vec3]
    uvs: tuple[tuple[Finite, Finite], tuple[Finite, Finite], tuple[Finite, Finite]] = (
        (0.0, 0.0), (1.0, 0.0), (0.0, 1.0))

    @model_validator(mode="after")
    def _not_degenerate(self) -> Triangle:
        a, b, c = (np.array(v) for v in self.vertices)
        if np.linalg.norm(np.cross(b - a, c - a)) < 1e-12:
            raise ValueError("the three vertices are collinear: the triangle has no area")
        return self


class Box(_Shape):
    """A parallelepiped: ``corner`` plus three ``edges``; or axis-aligned from ``min``/``max``."""

    type: Literal["box"] = "box"
    corner: Vec3 | None = None
    edges: tuple[Direction, Direction, Direction] | None = None
    min: Vec3 | None = None
    max: Vec3 | None = None

    @model_validator(mode="after")
    def _one_form(self) -> Box:
        oriented = self.corner is not None or self.edges is not None
        aligned = self.min is not None or self.max is not None
        if oriented == aligned:
            raise ValueError("give either corner + edges, or min + max")
        if oriented and (self.corner is None or self.edges is None):
            raise ValueError("corner and edges go together")
        if aligned:
            if self.min is None or self.max is None:
                raise ValueError("min and max go together")
            if any(hi <= lo for lo, hi in zip(self.min, self.max, strict=True)):
                raise ValueError("max must be greater than min on every axis")
        else:
            assert self.edges is not None
            if abs(np.linalg.det(np.array(self.edges))) < 1e-12:
                raise ValueError("the three edges are coplanar: the box has no volume")
        return self

    def corner_and_edges(self) -> tuple[np.ndarray, np.ndarray]:
        if self.min is not None and self.max is not None:
            lo, hi = np.array(self.min), np.array(self.max)
            return lo, np.diag(hi - lo)
        assert self.corner is not None and self.edges is not None
        return np.array(self.corner), np.array(self.edges, dtype=np.float64)


class Cylinder(_Shape):
    """A finite cylinder from the centre of its ``base`` to the centre of its ``top``."""

    type: Literal["cylinder"] = "cylinder"
    base: Vec3 = (0.0, 0.0, 0.0)
    top: Vec3 = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)
    capped: bool = True

    @model_validator(mode="after")
    def _has_height(self) -> Cylinder:
        if np.linalg.norm(np.subtract(self.top, self.base)) < 1e-12:
            raise ValueError("base and top coincide: zero height")
        return self


class Cone(_Shape):
    """A finite cone (or frustum when ``top_radius`` > 0) from ``base`` to ``top``."""

    type: Literal["cone"] = "cone"
    base: Vec3 = (0.0, 0.0, 0.0)
    top: Vec3 = (0.0, 1.0, 0.0)
    radius: float = Field(gt=0.0)
    top_radius: float = Field(default=0.0, ge=0.0)
    capped: bool = True

    @model_validator(mode="after")
    def _has_height(self) -> Cone:
        if np.linalg.norm(np.subtract(self.top, self.base)) < 1e-12:
            raise ValueError("base and top coincide: zero height")
        return self


class Torus(_Shape):
    """A torus around the object's y axis through its origin (POV-Ray's ``torus``): the circle
    of ``major_radius`` in the xz plane, swept by a tube of ``minor_radius``."""

    type: Literal["torus"] = "torus"
    major_radius: float = Field(gt=0.0, le=1e12)
    minor_radius: float = Field(gt=0.0, le=1e12)


class ArrayData:
    """An immutable NumPy array inside a scene model: compares by value, saves as a list."""

    __slots__ = ("array",)

    def __init__(self, array: np.ndarray) -> None:
        array = np.ascontiguousarray(array)
        array.setflags(write=False)
        self.array = array

    def __eq__(self, other: object) -> bool:
        if isinstance(other, ArrayData):
            return self.array.shape == other.array.shape and bool(
                np.array_equal(self.array, other.array)
            )
        return NotImplemented

    def __hash__(self) -> int:
        return hash((self.array.shape, self.array.tobytes()))

    def __len__(self) -> int:
        return len(self.array)

    def __array__(self, dtype=None, copy=None):
        return self.array if dtype is None else self.array.astype(dtype)

    def __repr__(self) -> str:
        return f"ArrayData(shape={self.array.shape}, dtype={self.array.dtype})"


def _array_of(columns: int, kind: str):
    def convert(value: object) -> ArrayData:
        if isinstance(value, ArrayData):
            value = value.array
        try:
            raw = np.asarray(value)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"expected a list of [{columns} numbers] rows") from None
        allowed = "iu" if kind == "i" else "iuf"
        # (numbers beyond 1e15, huge integers among them, are refused before this: types.py)
        if isinstance(value, list | tuple) and any(
            type(x) is bool for row in value for x in (row if isinstance(row, list | tuple)
                                                       else (row,))):
            raise ValueError(f"expected rows of {columns} numbers, not true/false")
        if raw.size and raw.dtype.kind not in allowed:
            if kind == "i" and raw.dtype.kind == "f":
                raise ValueError("indices must be whole numbers")
            what = "whole numbers" if kind == "i" else "numbers"
            raise ValueError(f"expected rows of {columns} {what} (no text, booleans or "
                             "ragged rows)")
        a = raw.astype(np.float64 if kind == "f" else np.int64)  # integers or floats by now
        if a.size == 0:
            a = a.reshape(0, columns)
        if a.ndim != 2 or a.shape[1] != columns:
            raise ValueError(f"expected rows of {columns} numbers, got shape {a.shape}")
        if kind == "f" and not np.isfinite(a).all():
            raise ValueError("values must be finite")
        if kind == "f" and a.size and np.abs(a).max() > MAX_MAGNITUDE:
            raise ValueError(f"a value is too large (scene values are limited to "
                             f"{MAX_MAGNITUDE:.0e} in magnitude)")
        return ArrayData(a.astype(np.float64 if kind == "f" else np.int64))

    return Annotated[
        Any,
        BeforeValidator(convert),
        PlainSerializer(lambda v: v.array.tolist(), return_type=list),
    ]


Points3 = _array_of(3, "f")
Points2 = _array_of(2, "f")
Indices3 = _array_of(3, "i")


class Mesh(_Shape):
    """A triangle mesh: from a model ``file`` (OBJ with its MTL, PLY, STL, OFF, glTF/GLB; path
    relative to the scene file) or from arrays: ``vertices`` (N x 3), ``faces`` (M x 3,
    0-based), optional per-vertex ``normals`` (N x 3) and ``uvs`` (N x 2).

    ``material`` overrides every material of the file. ``smooth``: unset uses the file's
    normals where it has them (flat shading where not); ``true`` computes smooth normals where
    the file has none, keeping edges sharper than ``crease_angle`` degrees; ``false`` shades
    flat. ``solid``: the mesh bounds a volume, so rays refract into and out of it (media).
    ``outside``: the material of the medium just outside a solid mesh (named, a preset or
    inline), for a surface between two media such as the ice around a water cavity: a ray
    crossing it bends once by the ratio of the two indices, whichever way it goes, and is
    then in the medium on the far side. Unset: the medium the ray arrives through (air,
    or a body it entered before).
    The same file used by several objects is loaded and stored once (instanced).
    """

    type: Literal["mesh"] = "mesh"
    file: str | None = Field(default=None, min_length=1)
    vertices: Points3 | None = None
    faces: Indices3 | None = None
    normals: Points3 | None = None
    uvs: Points2 | None = None
    smooth: bool | None = None
    crease_angle: float = Field(default=60.0, ge=0.0, le=180.0)
    solid: bool = True
    outside: str | Material | None = None

    def __init__(self, vertices: Any = None, faces: Any = None, normals: Any = None,
                 uvs: Any = None, **data: Any) -> None:
        for key, value in (("vertices", vertices), ("faces", faces), ("normals", normals),
                           ("uvs", uvs)):
            if value is not None:
                data[key] = value
        super().__init__(**data)

    @classmethod
    def from_file(cls, path: str | Path, **fields: Any) -> Mesh:
        """A mesh object for the model file at ``path``. A path that is not a readable regular
        file fails here; the model itself is read when the scene is compiled (or by
        :func:`whitted.assets.load_mesh`, which reads and checks it now)."""
        problem = path_problem(path)
        if problem is not None:
            raise SceneError(problem, file=str(path))
        return cls(file=str(path), **fields)

    @model_validator(mode="after")
    def _one_source(self) -> Mesh:
        inline = self.vertices is not None or self.faces is not None
        if (self.file is not None) == inline:
            raise ValueError("give either file, or vertices + faces")
        if inline:
            if self.vertices is None or self.faces is None:
                raise ValueError("vertices and faces go together")
            n = len(self.vertices)
            f = self.faces.array
            if f.size and (f.min() < 0 or f.max() >= n):
                raise ValueError(f"faces index vertices 0..{n - 1}; found {int(f.min())}.."
                                 f"{int(f.max())}")
            for key in ("normals", "uvs"):
                extra = getattr(self, key)
                if extra is not None and len(extra) != n:
                    raise ValueError(f"{key} has {len(extra)} rows, vertices has {n}")
        elif self.normals is not None or self.uvs is not None:
            raise ValueError("normals and uvs go with vertices + faces, not with file")
        return self


CSG_OPERATIONS = ("union", "intersection", "difference", "merge")
CSG_MAX_SOLIDS = 63  # kernels/layout.py CSG_MAX_ROWS: the walk keeps its states in int64 bits


class CSG(_Shape):
    """Constructive solid geometry (POV-Ray's ``union``, ``intersection``, ``difference`` and
    ``merge``) of solid ``objects``: spheres, boxes, capped cylinders and cones, tori and
    other CSG objects, to any depth. ``difference`` is the first object minus all the others;
    ``merge`` is a union without its inner surfaces (for glass). Meshes take part when they
    are closed (every edge shared by two triangles; checked when the scene is compiled), up
    to 2,000,000 triangles (a big one's crossings through a BVH of its own). ``material``
    is used by the children that have none; ``transform`` places the whole. Each surface
    keeps its child's material (a difference's cut shows the material of the object that
    cut it), and the
    solid is one body for refraction and absorption: its medium is its own ``material`` (or,
    unset, its first child's)."""

    type: Literal["csg"] = "csg"
    operation: Literal["union", "intersection", "difference", "merge"]
    objects: list[Shape] = Field(min_length=1)

    @model_validator(mode="before")
    @classmethod
    def _whole_tree_fits(cls, data: Any) -> Any:
        """The size of the whole tree, counted before its nested objects are validated (they
        are validated first, and each would report only its own part of a tree too big)."""
        if isinstance(data, dict):
            leaves, operations, depth = _tree_counts(data)
            if leaves + operations > CSG_MAX_SOLIDS:
                raise ValueError(_too_big(leaves, operations, depth))
        return data

    @model_validator(mode="after")
    def _solid_children(self) -> CSG:
        for k, child in enumerate(self.objects):
            what = child.name or child.type
            if isinstance(child, Plane | Rectangle | Disk | Triangle):
                raise ValueError(f"objects[{k}] ({what}): a {child.type} bounds no volume, "
                                 "so it cannot take part in CSG")
            if isinstance(child, Cylinder | Cone) and not child.capped:
                raise ValueError(f"objects[{k}] ({what}): an uncapped {child.type} is open, "
                                 "so it cannot take part in CSG")
            if isinstance(child, Mesh) and not child.solid:
                raise ValueError(f"objects[{k}] ({what}): a mesh with solid = false bounds "
                                 "no volume, so it cannot take part in CSG")
        leaves, rows = self.leaves(), self.rows()
        if leaves > CSG_MAX_SOLIDS or rows > CSG_MAX_SOLIDS:
            raise ValueError(_too_big(leaves, rows - leaves, _tree_counts(self)[2]))
        return self

    def rows(self) -> int:
        """Solids and operations in the tree (its compiled rows after the object's own)."""
        return 1 + sum(c.rows() if isinstance(c, CSG) else 1 for c in self.objects)

    def tree_lines(self, indent: str = "    ") -> list[str]:
        """The tree under this object, one line per child (nested children indented
        further): its index path, type, name and material."""
        lines = []

        def walk(node: CSG, prefix: str, depth: int) -> None:
            for k, child in enumerate(node.objects):
                mat = (child.material if isinstance(child.material, str)
                       else "inline" if child.material is not None else "inherited")
                label = f" '{child.name}'" if child.name else ""
                extra = f" {child.operation}" if isinstance(child, CSG) else ""
                lines.append(f"{indent * depth}{prefix}[{k}] {child.type}{extra}{label} "
                             f"material={mat}")
                if isinstance(child, CSG):
                    walk(child, f"{prefix}[{k}].objects", depth + 1)

        walk(self, "objects", 1)
        return lines

    def leaves(self) -> int:
        """Solids at the bottom of the tree (every nested CSG opened)."""
        return sum(c.leaves() if isinstance(c, CSG) else 1 for c in self.objects)


def _too_big(leaves: int, operations: int, depth: int) -> str:
    solids = f"{leaves} solid" + ("s" if leaves != 1 else "")
    ops = f"{operations} operation" + ("s" if operations != 1 else "")
    return (f"a CSG object holds at most {CSG_MAX_SOLIDS} solids and operations together; "
            f"this one has {solids} in {ops}, nested {depth} deep")


def _tree_counts(node: Any) -> tuple[int, int, int]:
    """(solids, operations, depth) of a CSG tree given as a CSG or as its table (a dict,
    not yet validated), counted without recursion."""
    leaves = operations = depth = 0
    stack = [(node, 1)]
    while stack:
        item, level = stack.pop()
        children = (item.get("objects") if isinstance(item, dict) else
                    item.objects if isinstance(item, CSG) else None)
        is_csg = (isinstance(item, CSG) or isinstance(item, dict)
                  and item.get("type", "csg" if item is node else None) == "csg")
        if is_csg and isinstance(children, list | tuple):
            operations += 1
            depth = max(depth, level)
            stack.extend((child, level + 1) for child in children)
        else:
            leaves += 1
    return leaves, operations, depth


Shape = Annotated[
    Sphere | Plane | Rectangle | Disk | Triangle | Box | Cylinder | Cone | Torus | Mesh | CSG,
    Field(discriminator="type"),
]
CSG.model_rebuild()
