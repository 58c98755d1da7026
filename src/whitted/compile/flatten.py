"""Scene description -> flat NumPy arrays (+ BVH) that the kernels read.

Transforms are baked into the shape's numbers wherever the shape family is closed under them
(planes, rectangles, triangles and boxes under any affine map; spheres, disks, cylinders and
cones under similarities). Only a quadric under a non-uniform scale or shear keeps a
world-to-object matrix and is intersected in its own space.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kernels.features import NO_INSTANCES_DTYPE
from ..kernels.layout import (
    FALLOFF_CODES,
    LIGHT_DIRECTION,
    LIGHT_DIRECTIONAL,
    LIGHT_DISK,
    LIGHT_DISK_U,
    LIGHT_DISK_V,
    LIGHT_DIST_SCALE,
    LIGHT_FALLOFF,
    LIGHT_POINT,
    LIGHT_POSITION,
    LIGHT_RADIANCE,
    LIGHT_RADIUS,
    LIGHT_SAMPLES,
    LIGHT_TYPE,
    MAT_AMBIENT,
    MAT_ATTEN,
    MAT_BLINN,
    MAT_COLOR,
    MAT_FRESNEL,
    MAT_IOR,
    MAT_KA,
    MAT_KD,
    MAT_KR,
    MAT_KS,
    MAT_KT,
    MAT_SHININESS,
    MAT_SPECULAR,
    MAT_TEXTURE,
    N_LIGHT_PARAMS,
    N_MAT_PARAMS,
    N_PRIM_INFO,
    N_PRIM_PARAMS,
    PRIM_MATERIAL,
    PRIM_OBJECT,
    PRIM_SOLID,
    PRIM_TYPE,
    PRIM_XFORM,
    SHAPE_BOX,
    SHAPE_DISK,
    SHAPE_FRUSTUM,
    SHAPE_MESH,
    SHAPE_PLANE,
    SHAPE_RECTANGLE,
    SHAPE_SPHERE,
    SHAPE_TRIANGLE,
    GeometryArrays,
    LightArrays,
    RenderParams,
)
from ..scene.lights import AmbientLight, DirectionalLight, DiskLight, PointLight
from ..scene.materials import Material
from ..scene.scene import RenderSettings, Scene
from ..scene.shapes import Box, Cone, Cylinder, Disk, Mesh, Plane, Rectangle, Sphere, Triangle
from .bvh import build_bvh
from .light_buffers import build_light_buffers
from .meshes import MeshSource, MeshTable
from .textures import compile_textures


@dataclass
class CompiledScene:
    """The scene as the kernels see it, plus what the Python side reports about it."""

    geometry: GeometryArrays
    materials: np.ndarray  # (M, N_MAT_PARAMS) float64
    lights: LightArrays  # the light table (ambient lights excluded) and light buffers
    ambient: tuple[float, float, float]
    bounds_min: np.ndarray  # (3,) of all bounded primitives (inf when there are none)
    bounds_max: np.ndarray
    build_seconds: float
    warnings: list[str]  # things the user should know (dropped triangles, missing textures)
    triangles: int = 0  # distinct mesh triangles stored (instances not multiplied)
    instanced_triangles: int = 0  # triangles in the scene counting every instance


class _Builder:
    """Primitive rows, gathered in blocks (one row per analytic shape, one block per
    flattened mesh) and joined at the end."""

    def __init__(self) -> None:
        self.blocks: list[tuple] = []
        self.xforms: list[np.ndarray] = []

    def add(self, typ, values, lo, hi, *, material, obj, solid, world_to_object=None):
        row = np.zeros((1, N_PRIM_PARAMS))
        row[0, : len(values)] = values
        xf = -1
        if world_to_object is not None:
            xf = len(self.xforms)
            self.xforms.append(world_to_object[:3, :4])
        self.add_block(typ, row, np.asarray(lo, np.float64).reshape(1, 3),
                       np.asarray(hi, np.float64).reshape(1, 3), material, obj, solid, xf)

    def add_block(self, typ, params, lo, hi, material, obj, solid, xf=-1):
        k = len(params)
        self.blocks.append((np.full(k, typ, np.int32), params, np.full(k, xf, np.int32),
                            np.broadcast_to(np.asarray(material, np.int32), (k,)),
                            np.full(k, obj, np.int32), np.full(k, int(solid), np.int32),
                            lo, hi))

    def columns(self):
        """types, params, xform index, material, object, solid, lo, hi: joined arrays."""
        if not self.blocks:
            return (np.zeros(0, np.int32), np.zeros((0, N_PRIM_PARAMS)), np.zeros(0, np.int32),
                    np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0, np.int32),
                    np.zeros((0, 3)), np.zeros((0, 3)))
        return tuple(np.concatenate([blk[k] for blk in self.blocks]) for k in range(8))


def _similarity_scale(linear: np.ndarray) -> float | None:
    """s when ``linear`` is s times a rotation (or reflection), else None."""
    gram = linear.T @ linear
    s2 = gram[0, 0]
    if np.allclose(gram, s2 * np.eye(3), rtol=1e-12, atol=1e-12 * max(s2, 1e-300)):
        return math.sqrt(s2)
    return None


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def _disk_bounds(center, normal, radius):
    n = _unit(normal)
    ext = radius * np.sqrt(np.clip(1.0 - n * n, 0.0, None))
    return center - ext, center + ext


def _corners_bounds(points: np.ndarray, matrix: np.ndarray | None = None):
    pts = np.asarray(points, dtype=np.float64)
    if matrix is not None:
        pts = pts @ matrix[:3, :3].T + matrix[:3, 3]
    return pts.min(axis=0), pts.max(axis=0)


def _box_corners(lo, hi):
    xs, ys, zs = (lo[0], hi[0]), (lo[1], hi[1]), (lo[2], hi[2])
    return np.array([[x, y, z] for x in xs for y in ys for z in zs])


def _tangent(normal) -> np.ndarray:
    """The u direction of planar texture mapping on a surface with this normal: world x made
    perpendicular to it (or -z for surfaces facing along x), so that seen from the front u
    runs right and v = normal x tangent runs up."""
    n = _unit(normal)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 0.0, -np.sign(n[0])])
    return _unit(helper - np.dot(helper, n) * n)


def _world_tangent(lin: np.ndarray, local_normal, world_normal) -> np.ndarray:
    """The object's own tangent carried by its transform, so a rotated shape turns its
    texture with it."""
    t = lin @ _tangent(local_normal)
    n = _unit(world_normal)
    return _unit(t - np.dot(t, n) * n)


def _add_shape(b: _Builder, shape, m: np.ndarray, material: int, obj: int) -> None:
    lin = m[:3, :3]
    to_world = m
    inv = np.linalg.inv(m)
    s = _similarity_scale(lin)

    def point(p):
        return lin @ np.asarray(p, dtype=np.float64) + m[:3, 3]

    def normal(n):
        return _unit(inv[:3, :3].T @ np.asarray(n, dtype=np.float64))

    if isinstance(shape, Sphere):
        c, r = np.array(shape.center), shape.radius
        if s is not None:
            cw = point(c)
            frame = (lin / s).T.reshape(-1)  # rows: the object's x, y, z axes in the world
            b.add(SHAPE_SPHERE, [*cw, r * s, *frame], cw - r * s, cw + r * s,
                  material=material, obj=obj, solid=True)
        else:
            cw = point(c)
            ext = r * np.linalg.norm(lin, axis=1)
            b.add(SHAPE_SPHERE, [*c, r, *np.eye(3).reshape(-1)], cw - ext, cw + ext,
                  material=material, obj=obj, solid=True, world_to_object=inv)
    elif isinstance(shape, Plane):
        nw = normal(shape.normal)
        b.add(SHAPE_PLANE, [*point(shape.point), *nw, *_world_tangent(lin, shape.normal, nw)],
              [-np.inf] * 3, [np.inf] * 3, material=material, obj=obj, solid=False)
    elif isinstance(shape, Rectangle):
        corner = point(shape.corner)
        e1, e2 = lin @ np.array(shape.edge1), lin @ np.array(shape.edge2)
        n = _unit(np.cross(e1, e2))
        du = np.cross(e2, n) / np.dot(e1, np.cross(e2, n))
        dv = np.cross(n, e1) / np.dot(e2, np.cross(n, e1))
        lo, hi = _corners_bounds([corner, corner + e1, corner + e2, corner + e1 + e2])
        b.add(SHAPE_RECTANGLE, [*corner, *e1, *e2, *n, *du, *dv], lo, hi, material=material,
              obj=obj, solid=False)
    elif isinstance(shape, Triangle):
        v0, v1, v2 = (point(v) for v in shape.vertices)
        e1, e2 = v1 - v0, v2 - v0
        n = _unit(np.cross(e1, e2))
        lo, hi = _corners_bounds([v0, v1, v2])
        uvs = np.array(shape.uvs, dtype=np.float64).reshape(-1)
        b.add(SHAPE_TRIANGLE, [*v0, *e1, *e2, *n, *uvs, -1.0], lo, hi, material=material,
              obj=obj, solid=False)
    elif isinstance(shape, Disk):
        c, n, r = np.array(shape.center), _unit(shape.normal), shape.radius
        if s is not None:
            cw, nw = point(c), normal(n)
            lo, hi = _disk_bounds(cw, nw, r * s)
            b.add(SHAPE_DISK, [*cw, *nw, r * s, *_world_tangent(lin, n, nw)], lo, hi,
                  material=material, obj=obj, solid=False)
        else:
            lo, hi = _disk_bounds(c, n, r)
            lo, hi = _corners_bounds(_box_corners(lo, hi), to_world)
            b.add(SHAPE_DISK, [*c, *n, r, *_tangent(n)], lo, hi, material=material, obj=obj,
                  solid=False, world_to_object=inv)
    elif isinstance(shape, Box):
        corner, edges = shape.corner_and_edges()
        corner_w = point(corner)
        edges_w = (lin @ edges.T).T  # rows are the three edge vectors
        inv_e = np.linalg.inv(edges_w.T)  # local = inv_e @ (p - corner)
        pts = [corner_w + i * edges_w[0] + j * edges_w[1] + k * edges_w[2]
               for i in (0, 1) for j in (0, 1) for k in (0, 1)]
        lo, hi = _corners_bounds(pts)
        b.add(SHAPE_BOX, [*corner_w, *inv_e.reshape(-1)], lo, hi, material=material, obj=obj,
              solid=True)
    elif isinstance(shape, Cylinder | Cone):
        base, top = np.array(shape.base), np.array(shape.top)
        r0 = shape.radius
        r1 = shape.radius if isinstance(shape, Cylinder) else shape.top_radius
        capped = shape.capped
        xf = None
        tangent = _tangent(top - base)
        if s is not None:
            tangent = _world_tangent(lin, top - base, lin @ (top - base))
            base, top, r0, r1 = point(base), point(top), r0 * s, r1 * s
        else:
            xf = inv
        axis = top - base
        h = float(np.linalg.norm(axis))
        axis = axis / h
        lo0, hi0 = _disk_bounds(base, axis, r0) if r0 > 0 else (base, base)
        lo1, hi1 = _disk_bounds(top, axis, r1) if r1 > 0 else (top, top)
        lo, hi = np.minimum(lo0, lo1), np.maximum(hi0, hi1)
        if xf is not None:
            lo, hi = _corners_bounds(_box_corners(lo, hi), to_world)
        b.add(SHAPE_FRUSTUM, [*base, *axis, h, r0, r1, float(capped), *tangent], lo, hi,
              material=material, obj=obj, solid=capped, world_to_object=xf)
    else:  # pragma: no cover - the scene model admits no other shape
        raise TypeError(f"cannot compile {type(shape).__name__}")


def material_row(mat: Material, texture: int = -1) -> np.ndarray:
    """The material table row of ``mat``; ``texture`` is its row in the texture table."""
    row = np.zeros(N_MAT_PARAMS)
    row[MAT_COLOR : MAT_COLOR + 3] = mat.color
    row[MAT_AMBIENT : MAT_AMBIENT + 3] = mat.ambient_color or mat.color
    row[MAT_SPECULAR : MAT_SPECULAR + 3] = mat.specular_color or (1.0, 1.0, 1.0)
    row[MAT_KA] = mat.ka
    row[MAT_KD] = mat.kd
    row[MAT_KS] = mat.ks
    row[MAT_SHININESS] = mat.shininess
    row[MAT_BLINN] = 1.0 if mat.specular_model == "blinn" else 0.0
    row[MAT_KR] = mat.kr
    row[MAT_KT] = mat.kt
    row[MAT_IOR] = mat.ior
    row[MAT_ATTEN : MAT_ATTEN + 3] = mat.attenuation_rgb()
    row[MAT_FRESNEL] = 1.0 if mat.fresnel else 0.0
    row[MAT_TEXTURE] = texture
    return row


class _MaterialTable:
    """Material rows and the textures they use, each stored once."""

    def __init__(self) -> None:
        self.rows: list[np.ndarray] = []
        self.index: dict[bytes, int] = {}
        self.textures: list = []
        self.texture_index: dict[str, int] = {}

    def add(self, mat: Material) -> int:
        tex = -1
        if mat.texture is not None:
            key = mat.texture.model_dump_json()
            if key not in self.texture_index:
                self.texture_index[key] = len(self.textures)
                self.textures.append(mat.texture)
            tex = self.texture_index[key]
        row = material_row(mat, tex)
        key = row.tobytes()
        if key not in self.index:
            self.index[key] = len(self.rows)
            self.rows.append(row)
        return self.index[key]


def _mesh_source(scene: Scene, obj_index: int, shape: Mesh, warnings: list[str]) -> MeshSource:
    if shape.file is not None:
        from ..assets import load_mesh

        data = load_mesh(scene.resolve_path(shape.file))
        warnings.extend(data.warnings)
        return MeshSource(label=shape.file, vertices=data.vertices, faces=data.faces,
                          normals=data.normals, uvs=data.uvs, face_material=data.face_material,
                          materials=list(data.materials))
    assert shape.vertices is not None and shape.faces is not None
    return MeshSource(
        label=f"objects[{obj_index}]",
        vertices=shape.vertices.array,
        faces=shape.faces.array,
        normals=None if shape.normals is None else shape.normals.array,
        uvs=None if shape.uvs is None else shape.uvs.array,
        face_material=np.zeros(len(shape.faces), np.int32),
        materials=[Material()],
    )


# A mesh whose copies (triangles x objects using it) come to at most this many triangles joins
# the scene BVH as triangle primitives, one copy per object; a bigger one is stored once and
# instanced. Small meshes are faster flattened (a scene without instances runs kernels
# specialised without the instance walks); big ones are cheaper instanced.
FLATTEN_LIMIT = 65_536
DEFAULT_UVS = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 1.0])  # barycentric: (u, v) = (b1, b2)


def _add_flat_mesh(b: _Builder, meshes: MeshTable, src: MeshSource, rows: np.ndarray,
                   shape: Mesh, m: np.ndarray, override: int, obj: int) -> int:
    """One object's copy of a small mesh, its transform baked in, as triangle primitives of the
    scene BVH (one BVH over analytic shapes and triangles). Returns the triangles added."""
    lin = m[:3, :3]
    v = np.asarray(src.vertices, np.float64) @ lin.T + m[:3, 3]
    kept = meshes.drawable(src, v)
    if kept is None:
        return 0
    faces, face_material, corners = kept
    t = len(faces)
    e1 = corners[:, 1] - corners[:, 0]
    e2 = corners[:, 2] - corners[:, 0]
    n = np.cross(e1, e2)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    params = np.empty((t, N_PRIM_PARAMS))
    params[:, 0:3] = corners[:, 0]
    params[:, 3:6] = e1
    params[:, 6:9] = e2
    params[:, 9:12] = n
    params[:, 12:18] = DEFAULT_UVS if src.uvs is None else np.asarray(src.uvs)[faces].reshape(
        t, 6)
    params[:, 18] = -1.0
    normals = None
    if shape.smooth is not False and src.normals is not None:  # the file's, carried along
        normals = np.asarray(src.normals, np.float64)[faces] @ np.linalg.inv(lin)
        length = np.linalg.norm(normals, axis=2, keepdims=True)
        normals = normals / np.where(length > 0, length, 1.0)
    elif shape.smooth:
        normals = meshes.corner_normals(src, v, faces, True, shape.crease_angle)
    if normals is not None:
        params[:, 18] = meshes.add_normal_rows(normals) + np.arange(t)
    material = np.asarray(rows, np.int32)[face_material] if override < 0 else override
    b.add_block(SHAPE_TRIANGLE, params, corners.min(axis=1), corners.max(axis=1), material, obj,
                shape.solid)
    return t


def _mesh_key(scene: Scene, shape: Mesh) -> tuple:
    """Objects with equal keys share one stored mesh (instancing)."""
    shading = (shape.smooth, shape.crease_angle if shape.smooth else None)
    if shape.file is not None:
        return ("file", str(scene.resolve_path(shape.file).resolve()), *shading)
    return ("arrays", id(shape.vertices), id(shape.faces), id(shape.normals), id(shape.uvs),
            *shading)


def _light_rows(scene: Scene) -> tuple[np.ndarray, tuple[float, float, float]]:
    rows = []
    ambient = np.zeros(3)
    for light in scene.lights:
        radiance = np.array(light.color) * light.intensity
        if isinstance(light, AmbientLight):
            ambient += radiance
            continue
        row = np.zeros(N_LIGHT_PARAMS)
        row[LIGHT_RADIANCE : LIGHT_RADIANCE + 3] = radiance
        if isinstance(light, PointLight):
            row[LIGHT_TYPE] = LIGHT_POINT
            row[LIGHT_POSITION : LIGHT_POSITION + 3] = light.position
        elif isinstance(light, DirectionalLight):
            row[LIGHT_TYPE] = LIGHT_DIRECTIONAL
            row[LIGHT_DIRECTION : LIGHT_DIRECTION + 3] = _unit(light.direction)
        elif isinstance(light, DiskLight):
            row[LIGHT_TYPE] = LIGHT_DISK
            n = _unit(light.normal)
            helper = np.array([1.0, 0, 0]) if abs(n[0]) < 0.9 else np.array([0, 1.0, 0])
            u = _unit(np.cross(n, helper))
            row[LIGHT_POSITION : LIGHT_POSITION + 3] = light.center
            row[LIGHT_DIRECTION : LIGHT_DIRECTION + 3] = n
            row[LIGHT_RADIUS] = light.radius
            row[LIGHT_SAMPLES] = light.samples or scene.render.shadow_samples
            row[LIGHT_DISK_U : LIGHT_DISK_U + 3] = u
            row[LIGHT_DISK_V : LIGHT_DISK_V + 3] = np.cross(n, u)
        if isinstance(light, PointLight | DiskLight):
            row[LIGHT_FALLOFF] = FALLOFF_CODES[light.falloff]
            row[LIGHT_DIST_SCALE] = light.dist_scale
        rows.append(row)
    table = np.array(rows, dtype=np.float64).reshape(len(rows), N_LIGHT_PARAMS)
    return table, (float(ambient[0]), float(ambient[1]), float(ambient[2]))


def _packed_nodes(bvh, dtype) -> tuple[np.ndarray, np.ndarray]:
    """A BVH's nodes in the kernel layout: boxes (M, 2, 3) and links (M, 2) (layout.py)."""
    box = np.empty((len(bvh.node_count), 2, 3), dtype)
    box[:, 0] = bvh.node_min
    box[:, 1] = bvh.node_max
    link = np.stack([bvh.node_offset, bvh.node_count], axis=1).astype(np.int32)
    return box, link


def compile_scene(scene: Scene, flatten_limit: int = FLATTEN_LIMIT) -> CompiledScene:
    """Flatten ``scene`` into the kernel layout and build the BVHs over its bounded shapes.

    A mesh whose copies (triangles x objects using it) come to at most ``flatten_limit``
    triangles becomes triangle primitives of the scene BVH, one copy per object; a bigger one
    is stored once and instanced."""
    import time
    from collections import Counter

    start = time.perf_counter()
    b = _Builder()
    materials = _MaterialTable()
    meshes = MeshTable()
    mesh_of: dict[tuple, object] = {}
    sources: dict[tuple, tuple[MeshSource, np.ndarray]] = {}
    warnings: list[str] = []
    instanced = 0
    flat = 0
    uses = Counter(_mesh_key(scene, s) for s in scene.objects if isinstance(s, Mesh))
    for obj_index, shape in enumerate(scene.objects):
        m = shape.transform.matrix() if shape.transform is not None else np.eye(4)
        if isinstance(shape, Mesh):
            key = _mesh_key(scene, shape)
            override = -1 if shape.material is None else materials.add(
                scene.material_of(obj_index))
            if key not in sources:
                src = _mesh_source(scene, obj_index, shape, warnings)
                rows = np.array([materials.add(mat) for mat in src.materials], np.int32)
                sources[key] = (src, rows)
            src, rows = sources[key]
            if uses[key] * len(src.faces) <= flatten_limit:
                added = _add_flat_mesh(b, meshes, src, rows, shape, m, override, obj_index)
                flat += added
                instanced += added
                continue
            if key not in mesh_of:
                mesh_of[key] = meshes.add(src, rows, shape.smooth, shape.crease_angle)
            stored = mesh_of[key]
            if stored is None:
                continue
            identity = np.array_equal(m, np.eye(4))
            lo, hi = _corners_bounds(_box_corners(stored.lo, stored.hi), None if identity else m)
            b.add(SHAPE_MESH, [stored.index], lo, hi, material=override, obj=obj_index,
                  solid=shape.solid, world_to_object=None if identity else np.linalg.inv(m))
            instanced += stored.triangles
            continue
        _add_shape(b, shape, m, materials.add(scene.material_of(obj_index)), obj_index)
    warnings.extend(meshes.warnings)

    prim_type, params, prim_xform, prim_material, prim_object, prim_solid, lo, hi = b.columns()
    finite = np.all(np.isfinite(lo) & np.isfinite(hi), axis=1)
    is_instance = prim_type == SHAPE_MESH
    bounded = np.flatnonzero(finite & ~is_instance).astype(np.int32)
    instances = np.flatnonzero(is_instance).astype(np.int32)
    unbounded = np.flatnonzero(~finite)
    bvh = build_bvh(lo[bounded], hi[bounded])
    inst_bvh = build_bvh(lo[instances], hi[instances])
    prim_info = np.empty((len(prim_type), N_PRIM_INFO), np.int32)
    prim_info[:, PRIM_TYPE] = prim_type
    prim_info[:, PRIM_XFORM] = prim_xform
    prim_info[:, PRIM_MATERIAL] = prim_material
    prim_info[:, PRIM_SOLID] = prim_solid
    prim_info[:, PRIM_OBJECT] = prim_object
    node_box, node_link = _packed_nodes(bvh, np.float64)
    # float32 marks a scene without instances: kernels specialised for it (features.py)
    inst_box, inst_link = _packed_nodes(
        inst_bvh, np.float64 if len(instances) else NO_INSTANCES_DTYPE)
    geometry = GeometryArrays(
        prim_info=prim_info,
        prim_params=params,
        xforms=np.array(b.xforms, dtype=np.float64).reshape(len(b.xforms), 3, 4),
        node_box=node_box,
        node_link=node_link,
        node_prims=np.ascontiguousarray(bounded[bvh.prim_order], dtype=np.int32),
        unbounded=unbounded.astype(np.int32),
        inst_box=inst_box,
        inst_link=inst_link,
        inst_prims=np.ascontiguousarray(instances[inst_bvh.prim_order], dtype=np.int32),
        **meshes.arrays(),
        **compile_textures(materials.textures, scene.resolve_path)._asdict(),
    )
    mat_table = np.array(materials.rows, dtype=np.float64).reshape(len(materials.rows),
                                                                    N_MAT_PARAMS)
    light_table, ambient = _light_rows(scene)
    lights = build_light_buffers(geometry, mat_table, light_table,
                                 has_instances=len(instances) > 0)
    if finite.any():
        bmin, bmax = lo[finite].min(axis=0), hi[finite].max(axis=0)
    else:
        bmin, bmax = np.full(3, np.inf), np.full(3, -np.inf)
    return CompiledScene(
        geometry=geometry,
        materials=mat_table,
        lights=lights,
        ambient=ambient,
        bounds_min=bmin,
        bounds_max=bmax,
        build_seconds=time.perf_counter() - start,
        warnings=warnings,
        triangles=meshes.n_tris + flat,
        instanced_triangles=instanced,
    )


def auto_epsilon(scene: Scene, compiled: CompiledScene) -> float:
    """Offset of secondary-ray origins: the user's, or 1e-7 of the scene's coordinate scale."""
    if scene.render.epsilon > 0:
        return scene.render.epsilon
    scale = max(1.0, float(np.max(np.abs(scene.camera.position))))
    if np.all(np.isfinite(compiled.bounds_min)):
        scale = max(scale, float(np.max(np.abs(compiled.bounds_min))),
                    float(np.max(np.abs(compiled.bounds_max))))
    for i in compiled.geometry.unbounded:
        scale = max(scale, float(np.max(np.abs(compiled.geometry.prim_params[i, :3]))))
    return 1e-7 * scale


def render_params(scene: Scene, compiled: CompiledScene, settings: RenderSettings) -> RenderParams:
    cam = scene.camera
    right, up, forward = cam.basis()
    hw, hh = cam.half_extents(settings.width, settings.height)
    bg = scene.background
    top = bg.gradient.top if bg.gradient else bg.color
    bottom = bg.gradient.bottom if bg.gradient else bg.color

    def t3(v) -> tuple[float, float, float]:
        return (float(v[0]), float(v[1]), float(v[2]))

    return RenderParams(
        width=int(settings.width),
        height=int(settings.height),
        samples=int(settings.samples),
        max_depth=int(settings.max_depth),
        min_weight=float(settings.min_weight),
        epsilon=float(auto_epsilon(scene, compiled)),
        seed=int(settings.seed),
        ambient=t3(compiled.ambient),
        background_top=t3(top),
        background_bottom=t3(bottom),
        camera_origin=t3(cam.position),
        camera_right=t3(np.asarray(right) * hw),
        camera_up=t3(np.asarray(up) * hh),
        camera_forward=t3(forward),
        orthographic=int(cam.projection == "orthographic"),
    )
