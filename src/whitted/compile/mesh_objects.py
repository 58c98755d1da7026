"""Scene mesh objects -> flattened triangle primitives or instances of a stored mesh.

A mesh whose copies (triangles x objects using it) come to at most ``FLATTEN_LIMIT``
triangles joins the scene BVH as triangle primitives, one copy per object, its transform baked
in; a bigger one is stored once (``meshes.MeshTable``) and each object becomes an instance.
"""

from __future__ import annotations

import numpy as np

from ..kernels.layout import N_PRIM_PARAMS, SHAPE_TRIANGLE
from ..scene.materials import Material
from ..scene.scene import Scene
from ..scene.shapes import Mesh
from .meshes import MeshSource, MeshTable
from .primitives import PrimitiveRows


def mesh_source(scene: Scene, obj_index: int, shape: Mesh, warnings: list[str]) -> MeshSource:
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


def add_flat_mesh(b: PrimitiveRows, meshes: MeshTable, src: MeshSource, rows: np.ndarray,
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


def geometry_key(scene: Scene, shape: Mesh) -> tuple:
    """Mesh objects with equal keys have the same triangles: one model file, or one set of
    inline arrays (the same Python arrays, as a Mesh reused or copied with ``model_copy``)."""
    if shape.file is not None:
        return ("file", str(scene.resolve_path(shape.file).resolve()))
    return ("arrays", id(shape.vertices), id(shape.faces), id(shape.normals), id(shape.uvs))


def mesh_key(scene: Scene, shape: Mesh) -> tuple:
    """Objects with equal keys share one stored mesh (instancing): the same triangles
    (:func:`geometry_key`) shaded the same way."""
    # the medium outside is part of the stored mesh's material rows
    outside = None if shape.outside is None else repr(shape.outside)
    shading = (shape.smooth, shape.crease_angle if shape.smooth else None, outside)
    return (*geometry_key(scene, shape), *shading)
