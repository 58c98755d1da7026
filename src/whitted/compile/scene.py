"""Scene description -> the compiled scene: flat NumPy arrays and BVHs that the kernels read.

``compile_scene`` walks the scene's objects once: analytic shapes become primitive rows
(``shapes.py``), mesh objects become flattened triangles or instances (``mesh_objects.py``),
materials and lights become tables (``materials.py``, ``lights.py``); then it builds the scene
BVH over the bounded primitives, the instances' own BVH, and the light buffers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernels.features import EXTRAS_DTYPE, NO_INSTANCES_DTYPE
from ..kernels.layout import (
    FIRST_EXTRA_SHAPE,
    N_MAT_PARAMS,
    N_PRIM_INFO,
    PRIM_FLIP,
    PRIM_MATERIAL,
    PRIM_MEDIUM,
    PRIM_OBJECT,
    PRIM_SOLID,
    PRIM_TYPE,
    PRIM_XFORM,
    SHAPE_MESH,
    GeometryArrays,
    LightArrays,
)
from ..scene.materials import Material
from ..scene.scene import Scene
from ..scene.shapes import CSG, Mesh
from .bvh_frame import choose_frame, rotation_of
from .csg import add_csg
from .embree import attach_embree
from .geometry import box_corners, corners_bounds
from .light_buffers import LIGHT_BUFFER_RES, build_light_buffers
from .lights import light_rows
from .materials import MaterialTable
from .mesh_objects import FLATTEN_LIMIT, add_flat_mesh, geometry_key, mesh_key, mesh_source
from .meshes import MeshSource, MeshTable
from .primitives import PrimitiveRows
from .reuse import cached_build_bvh
from .shapes import add_shape
from .textures import compile_textures
from .wide_bvh import wide_nodes


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
    mesh_tracer: str = "whitted"  # who traces the instanced meshes: whitted or embree
    instanced_triangles: int = 0  # triangles in the scene counting every instance
    #: (P, 3) world bounds of each primitive (inf for the unbounded): the caustics' targets
    prim_lo: np.ndarray | None = None
    prim_hi: np.ndarray | None = None


#: a model file's typical bytes per triangle (the default scene's OBJ has 58, with normals;
#: binary PLY 13-20, binary STL 50): scene_needs_builders' estimate of a model's triangles
#: before reading it. An estimate: a wrong one costs time, never a different result
_BYTES_PER_TRIANGLE = {".obj": 40, ".ply": 20, ".stl": 50, ".off": 30, ".gltf": 20, ".glb": 20}


def scene_needs_builders(scene: Scene) -> bool:
    """Whether compiling ``scene`` may run a builder on an input too large for its Python
    twin (jit/python_twins.py), judged before reading any model: the objects, the inline
    meshes' triangles and each model file's triangles estimated from its size together over
    the BVH builder's limit, or a model file over the OBJ reader's. A first render of such a
    scene has its compile helper compile the builders too."""
    from ..assets.obj_scan import PYTHON_LIMIT_BYTES
    from .bvh import PYTHON_LIMIT

    primitives = len(scene.objects)
    for shape in scene.objects:
        if not isinstance(shape, Mesh):
            continue
        if shape.file is None:
            primitives += len(shape.faces) if shape.faces is not None else 0
            continue
        path = scene.resolve_path(shape.file)
        try:
            size = path.stat().st_size
        except OSError:
            continue  # reported where the model is read
        if size > PYTHON_LIMIT_BYTES:
            return True
        primitives += size // _BYTES_PER_TRIANGLE.get(path.suffix.lower(), 20)
    return primitives > PYTHON_LIMIT


def scene_needs_general_kernels(scene: Scene) -> bool:
    """Whether ``scene`` runs the general render kernels whatever its model files hold: it
    has a CSG object, or an analytic shape whose row only the general kernels intersect (a
    torus), found by writing one shape of each class into rows as :func:`compile_scene`
    does and asking the row's type as it does. Mesh instances (a model kept whole) are
    found only by compiling the scene: False says nothing of them. A first render of such a
    scene compiles the general kernels only, not the plain ones first."""
    from .shapes import ROWS

    seen: set[type] = set()
    for shape in scene.objects:
        if isinstance(shape, CSG):
            return True
        if type(shape) in seen or type(shape) not in ROWS:
            continue
        seen.add(type(shape))
        rows = PrimitiveRows()
        add_shape(rows, shape, np.eye(4), 0, 0)
        if any(bool((block[0] >= FIRST_EXTRA_SHAPE).any()) for block in rows.blocks):
            return True
    return False


#: scene BVHs of this many bounded primitives are built with the SAH on all three axes
ALL_AXES_FROM = 4096
ALL_AXES_UP_TO = 1 << 20  # past this the build's time matters more (three times the binning)
#: the instance BVH's cost of a node visit against one instance's test (an Embree call or a
#: walk of the instance's mesh): small, so the SAH parts the instances down to leaves of one
#: (instances100 at one thread: 0.89 of the render time with leaves of up to two; the
#: closest-hit walks and the shadow rays' lists test each instance's own box)
INSTANCE_TRAVERSAL_COST = 0.1


def packed_nodes(bvh, dtype) -> tuple[np.ndarray, np.ndarray]:
    """A BVH's nodes in the kernel layout: boxes (M, 2, 3) and links (M, 2) (layout.py)."""
    box = np.empty((len(bvh.node_count), 2, 3), dtype)
    box[:, 0] = bvh.node_min
    box[:, 1] = bvh.node_max
    link = np.stack([bvh.node_offset, bvh.node_count], axis=1).astype(np.int32)
    return box, link


def compile_scene(scene: Scene, flatten_limit: int = FLATTEN_LIMIT, *,
                  light_buffers: bool = True, mesh_tracer: str | None = None,
                  threads: int = 1) -> CompiledScene:
    """Flatten ``scene`` into the kernel layout and build the BVHs over its bounded shapes.

    A mesh whose copies (triangles x objects using it) come to at most ``flatten_limit``
    triangles becomes triangle primitives of the scene BVH, one copy per object; a bigger one
    is stored once and instanced. ``light_buffers=False`` skips the point lights' light
    buffers: the same image (shadow rays then walk the BVH), built in a fraction of the time,
    which is what a small interactive preview wants. ``threads`` is how many threads may
    build the light buffers (the render's own count: the same arrays on any number)."""
    import time
    from collections import Counter

    start = time.perf_counter()
    b = PrimitiveRows()
    materials = MaterialTable()
    meshes = MeshTable(mesh_tracer or scene.render.mesh_tracer)
    # One mesh table entry per distinct mesh (mesh_key), shared by every object using it:
    # plain instances and big CSG leaves alike (a CSG leaf needs only the triangles and
    # their BVH, so it also takes an entry of the same triangles shaded otherwise).
    mesh_of: dict[tuple, object] = {}
    mesh_of_geometry: dict[tuple, object] = {}
    loaded: dict[tuple, MeshSource] = {}  # each model file read once
    sources: dict[tuple, tuple[MeshSource, np.ndarray]] = {}
    warnings: list[str] = []
    instanced = 0
    flat = 0
    rotations: list[tuple[int, np.ndarray]] = []  # (triangles, rotation) of flattened meshes

    def source_of(obj_index: int, shape: Mesh) -> MeshSource:
        key = geometry_key(scene, shape)
        if key not in loaded:
            loaded[key] = mesh_source(scene, obj_index, shape, warnings)
        return loaded[key]

    def stored_mesh(key: tuple, shape: Mesh, src: MeshSource, rows: np.ndarray):
        """The mesh table entry of ``key`` (stored now if it is new), or None when the mesh
        has no triangle to draw."""
        if key not in mesh_of:
            mesh_of[key] = meshes.add(src, rows, shape.smooth, shape.crease_angle)
            mesh_of_geometry.setdefault(geometry_key(scene, shape), mesh_of[key])
        return mesh_of[key]

    def outside_row(shape: Mesh) -> int:
        return -1 if shape.outside is None else materials.add(
            scene.resolve_material(shape.outside))

    uses = Counter(mesh_key(scene, s) for s in scene.objects if isinstance(s, Mesh))
    for obj_index, shape in enumerate(scene.objects):
        m = shape.transform.matrix() if shape.transform is not None else np.eye(4)
        if isinstance(shape, Mesh):
            key = mesh_key(scene, shape)
            outside = outside_row(shape)
            override = -1 if shape.material is None else materials.add(
                scene.material_of(obj_index), outside)
            if key not in sources:
                src = source_of(obj_index, shape)
                rows = np.array([materials.add(mat, outside) for mat in src.materials],
                                np.int32)
                sources[key] = (src, rows)
            src, rows = sources[key]
            if uses[key] * len(src.faces) <= flatten_limit:
                added = add_flat_mesh(b, meshes, src, rows, shape, m, override, obj_index)
                turn = rotation_of(m)
                if added and turn is not None:
                    rotations.append((added, turn))
                flat += added
                instanced += added
                continue
            stored = stored_mesh(key, shape, src, rows)
            if stored is None:
                continue
            identity = np.array_equal(m, np.eye(4))
            lo, hi = corners_bounds(box_corners(stored.lo, stored.hi), None if identity else m)
            b.add(SHAPE_MESH, [stored.index], lo, hi, material=override, obj=obj_index,
                  solid=shape.solid, world_to_object=None if identity else np.linalg.inv(m))
            instanced += stored.triangles
            continue
        if isinstance(shape, CSG):
            def emit_mesh(src, child, cm, mat, obj_index=obj_index):
                # a mesh child without a material takes the CSG's, unless its file gives
                # materials of its own (an OBJ's MTL): whitted's default for a file that
                # names none is not one
                own = (child.material is None and child.file is not None
                       and any(x != Material() for x in src.materials))
                rows = np.array([materials.add(x) for x in src.materials], np.int32)
                first = b.rows
                count = add_flat_mesh(b, meshes, src, rows, child, cm,
                                      -1 if own else materials.add(mat), obj_index)
                return first, count

            def store_mesh(src, child):  # a big mesh leaf's crossings: its BVH, shared
                key, same = mesh_key(scene, child), geometry_key(scene, child)
                if key not in mesh_of and same in mesh_of_geometry:
                    stored = mesh_of_geometry[same]
                else:
                    outside = outside_row(child)
                    stored = stored_mesh(key, child, src, np.array(
                        [materials.add(x, outside) for x in src.materials], np.int32))
                return None if stored is None else (stored.index, stored.triangles)

            add_csg(b, shape, m, materials.add, scene.resolve_material, obj_index,
                    scene.material_of(obj_index),
                    lambda child, where, i=obj_index: source_of(i, child),
                    emit_mesh, store_mesh)
            continue
        add_shape(b, shape, m, materials.add(scene.material_of(obj_index)), obj_index)
    warnings.extend(meshes.warnings)

    prim_type, params, prim_xform, prim_material, prim_object, prim_solid, lo, hi = b.columns()
    walked, prim_flip, prim_medium = b.extra_columns()
    finite = np.all(np.isfinite(lo) & np.isfinite(hi), axis=1) & walked
    is_instance = prim_type == SHAPE_MESH
    bounded = np.flatnonzero(finite & ~is_instance).astype(np.int32)
    instances = np.flatnonzero(is_instance).astype(np.int32)
    unbounded = np.flatnonzero(~finite & walked)
    # the scene BVH's boxes in the orientation of its biggest flattened mesh, where that makes
    # them smaller (bvh_frame.py)
    bvh_frame, frame_lo, frame_hi = choose_frame(rotations, prim_type[bounded],
                                                 params[bounded], prim_xform[bounded],
                                                 lo[bounded], hi[bounded])
    # a big scene BVH (flattened meshes) is split on the best of all three axes: nested,
    # turned shells gave 4-11 % faster renders (docs/performance.md); small ones keep theirs
    bvh = cached_build_bvh(frame_lo, frame_hi,
                           all_axes=ALL_AXES_FROM <= len(bounded) <= ALL_AXES_UP_TO)
    # an instance costs a walk of its own mesh (an Embree call) where a box costs a few
    # compares: the instance BVH splits down to leaves of one instance where the SAH allows
    inst_bvh = cached_build_bvh(lo[instances], hi[instances],
                                traversal_cost=INSTANCE_TRAVERSAL_COST)
    prim_info = np.empty((len(prim_type), N_PRIM_INFO), np.int32)
    prim_info[:, PRIM_TYPE] = prim_type
    prim_info[:, PRIM_XFORM] = prim_xform
    prim_info[:, PRIM_MATERIAL] = prim_material
    prim_info[:, PRIM_SOLID] = prim_solid
    prim_info[:, PRIM_OBJECT] = prim_object
    prim_info[:, PRIM_FLIP] = prim_flip
    prim_info[:, PRIM_MEDIUM] = prim_medium
    node_box, node_link = packed_nodes(bvh, np.float64)
    # a scene with mesh instances or with tori or CSG objects runs the general kernels
    # (float64 inst_box, int64 unbounded); one with neither the plain ones (features.py)
    general = len(instances) > 0 or bool((prim_type >= FIRST_EXTRA_SHAPE).any())
    inst_box, inst_link = packed_nodes(inst_bvh, np.float64 if general else NO_INSTANCES_DTYPE)
    mat_table = np.array(materials.rows, dtype=np.float64).reshape(len(materials.rows),
                                                                    N_MAT_PARAMS)
    tracer = meshes.tracer or "whitted"
    mesh_arrays = meshes.arrays()
    mesh_arrays["mesh_info"] = attach_embree(tracer, mesh_arrays["mesh_info"], meshes.vertices,
                                             meshes.local_faces, meshes.tri_material, mat_table)
    geometry = GeometryArrays(
        prim_info=prim_info,
        prim_params=params,
        xforms=np.array(b.xforms, dtype=np.float64).reshape(len(b.xforms), 3, 4),
        node_box=node_box,
        node_link=node_link,
        node_wide=wide_nodes(bvh),
        node_prims=np.ascontiguousarray(bounded[bvh.prim_order], dtype=np.int32),
        bvh_frame=bvh_frame,
        unbounded=unbounded.astype(EXTRAS_DTYPE if general else np.int32),
        inst_box=inst_box,
        inst_link=inst_link,
        inst_prims=np.ascontiguousarray(instances[inst_bvh.prim_order], dtype=np.int32),
        **mesh_arrays,
        **compile_textures(materials.textures, scene.resolve_path)._asdict(),
    )
    light_table, ambient = light_rows(scene)
    lights = build_light_buffers(geometry, mat_table, light_table,
                                 res=LIGHT_BUFFER_RES if light_buffers else 0,
                                 threads=threads)
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
        mesh_tracer=tracer,
        prim_lo=lo,
        prim_hi=hi,
    )
