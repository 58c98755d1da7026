"""The flat array layout shared by the compiler (which writes it) and the kernels (which read it).

Primitives: ``prim_info[i, PRIM_TYPE]`` is one of the ``SHAPE_*`` codes and ``prim_params[i]``
holds the shape's numbers in the order listed next to each code. All positions are in the
primitive's own space; ``prim_info[i, PRIM_XFORM] >= 0`` names a 3x4 world-to-object matrix
in ``xforms`` (used for mesh instances under any transform but the identity, and for quadrics
under a non-similarity transform; every other transform is baked into the numbers).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

# shape codes and their parameters (prim_params columns)
SHAPE_SPHERE = 0  # center 0:3, radius 3
SHAPE_PLANE = 1  # point 0:3, unit normal 3:6
# corner 0:3, edge1 3:6, edge2 6:9, unit normal 9:12, dual u 12:15, dual v 15:18
SHAPE_RECTANGLE = 2
SHAPE_DISK = 3  # center 0:3, unit normal 3:6, radius 6
SHAPE_TRIANGLE = 4  # v0 0:3, edge1 3:6, edge2 6:9, unit normal 9:12, corner uvs 12:18,
# row of tri_normals with its corner normals 18 (-1: flat)
SHAPE_BOX = 5  # corner 0:3, inverse edge matrix rows 3:12 (local = M^-1 (p - corner) in [0,1]^3)
SHAPE_FRUSTUM = 6  # base 0:3, unit axis 3:6, height 6, base radius 7, top radius 8, capped 9
SHAPE_MESH = 7  # an instance of a triangle mesh: mesh index 0 (a row of mesh_info)
# The shapes below need the kernels compiled for scenes with them (features.py has_extras):
# a torus about its own y axis: centre 0:3, the object's x, y, z axes in world space (unit)
# 3:12, major radius 12, minor radius 13
SHAPE_TORUS = 8
# a CSG object (kernels/csg.py): the rows after it, count 0, are its tree in postfix order
# (leaves: ordinary solid rows; operations: SHAPE_CSG_OP rows); leaves 1; its box: lower
# corner 2:5, upper corner 5:8
SHAPE_CSG = 9
SHAPE_CSG_OP = 10  # an operation of a CSG tree: CSG_* code 0, number of operands 1
# a closed mesh in a CSG tree: its triangles are the rows first 0 .. first + count 1 - 1
# (flattened, in no BVH, after the tree's rows)
SHAPE_CSG_MESH = 11
FIRST_EXTRA_SHAPE = SHAPE_TORUS

# CSG operation codes (SHAPE_CSG_OP rows)
CSG_UNION = 0
CSG_INTERSECTION = 1
CSG_DIFFERENCE = 2
CSG_MERGE = 3
CSG_MAX_LEAVES = 63  # solids in one CSG tree (the inside states are the bits of an int64)
CSG_MAX_ROWS = 63  # leaves and operations together (scene/shapes.py CSG_MAX_SOLIDS)

# texture-space frames of the analytic shapes (after their own numbers above)
SPHERE_FRAME = 4  # 4:13 the object's x, y, z axes in world space (unit), for spherical uv
PLANE_TANGENT = 6  # 6:9 unit tangent (u direction); v = normal x tangent
DISK_TANGENT = 7  # 7:10
TRIANGLE_UV = 12  # 12:18 texture coordinates of the three corners
TRIANGLE_NORMALS = 18  # row of tri_normals (smooth-shaded triangles of a flattened mesh), or -1
FRUSTUM_TANGENT = 10  # 10:13 unit vector perpendicular to the axis where u = 0

N_PRIM_PARAMS = 19

# material columns
MAT_COLOR = 0
MAT_AMBIENT = 3
MAT_SPECULAR = 6
MAT_KA = 9
MAT_KD = 10
MAT_KS = 11
MAT_SHININESS = 12
MAT_BLINN = 13
MAT_KR = 14
MAT_KT = 15
MAT_IOR = 16
MAT_ATTEN = 17
MAT_FRESNEL = 20
MAT_TEXTURE = 21  # row of the texture table multiplying the colour, -1 for none
# row of the medium just outside a solid mesh's surface (the ice around a water cavity), -1:
# whatever medium the ray arrives through
MAT_OUTSIDE = 22
N_MAT_PARAMS = 23

# mesh_info columns (one row per distinct mesh; instances point at a row)
MESH_ROOT = 0  # root node in the mesh_node_* arrays
MESH_TRI_OFFSET = 1  # first triangle in mesh_faces
MESH_TRI_COUNT = 2
MESH_NORMALS = 3  # row of tri_normals holding triangle 0's corner normals, -1: flat shading
MESH_UVS = 4  # row of tri_uvs holding triangle 0's corner uvs, -1: none
# Embree (compile/embree.py, kernels/embree.py): five 64-bit addresses, each as two int32
# columns (low half, high half) from MESH_EMBREE + 2 * k: the mesh's Embree scenes
# (k = EMBREE_ALL, EMBREE_OPAQUE, EMBREE_CLEAR; 0: none) and the addresses of rtcIntersect1
# and rtcOccluded1 (k = EMBREE_INTERSECT, EMBREE_OCCLUDED). In mesh_info rather than an array
# of their own: one more array in GeometryArrays made seed000 render 25 % slower (every
# kernel call that is not inlined passes each array's every part)
MESH_EMBREE = 5
N_MESH_INFO = 15

# light columns (ambient lights are summed into one colour and not stored here)
LIGHT_POINT = 1
LIGHT_DIRECTIONAL = 2
LIGHT_DISK = 3

LIGHT_TYPE = 0
LIGHT_RADIANCE = 1  # colour * intensity, 1:4
LIGHT_POSITION = 4  # point position / disk centre, 4:7
LIGHT_DIRECTION = 7  # directional: unit travel direction; disk: unit normal, 7:10
LIGHT_RADIUS = 10
LIGHT_SAMPLES = 11
LIGHT_FALLOFF = 12  # 0 none, 1 linear (dist_scale / d), 2 inverse square
LIGHT_DIST_SCALE = 13
LIGHT_DISK_U = 14  # 14:17, unit tangent of the disk
LIGHT_DISK_V = 17  # 17:20, unit bitangent
LIGHT_BUFFER = 20  # point lights: first row of their cells in LightArrays.buffer_cells, or -1
LIGHT_BUFFER_SIDE = 21  # cells along a side of each cube face of that light buffer
N_LIGHT_PARAMS = 22

# light-buffer cell columns (LightArrays.buffer_cells)
CELL_FIRST = 0
CELL_COUNT = 1  # -1: too many primitives to list (shadow rays through the cell walk the BVH)
CELL_OPAQUE = 2

FALLOFF_CODES = {"none": 0, "linear": 1, "inverse_square": 2}

# ray counters (columns of the per-tile counter array)
RAY_PRIMARY = 0
RAY_SHADOW = 1
RAY_REFLECTION = 2
RAY_REFRACTION = 3
N_RAY_KINDS = 4

MAX_MEDIA = 8  # nesting depth of media a ray can be inside


# prim_info columns
PRIM_TYPE = 0  # SHAPE_* code
PRIM_XFORM = 1  # row of xforms (world to object), -1 when the numbers are in world space
PRIM_MATERIAL = 2  # row of the material table (-1: a mesh instance using its triangles')
PRIM_SOLID = 3  # 1 when it bounds a volume (rays enter and leave media)
PRIM_OBJECT = 4  # index of the scene object it came from
# 1 when the surface of a CSG leaf faces the other way in its solid (a difference's cut);
# read only by kernels for scenes with extra shapes (features.py has_extras)
PRIM_FLIP = 5
# material row of the body whose medium a CSG leaf's surface bounds (-1: the surface's own)
PRIM_MEDIUM = 6
N_PRIM_INFO = 7

# BVH layout (every level): node_box[n] = (lower corner, upper
# corner); node_link[n] = (offset, count): a leaf (count > 0) holds entries offset .. offset +
# count - 1 of its index list; an interior node (count 0) has its left child at n + 1 and its
# right child at offset.
LINK_OFFSET = 0
LINK_COUNT = 1
# the scene BVH's eight-wide nodes (compile/wide_bvh.py), which any-hit walks take:
# node_wide[w, 0:3, c] and node_wide[w, 3:6, c] the corners of child c (rounded outward),
# node_wide[w, WIDE_LINK, c] an interior child's wide node or a leaf's first entry in
# node_prims, node_wide[w, WIDE_COUNT, c] 0 (interior), the leaf's primitive count, or -1 (no
# child in that lane); whole numbers held exactly in float32 (below 2**24; a scene BVH
# with more leaf entries has no wide nodes and its any-hit walks take the binary nodes)
WIDE = 8
WIDE_LINK = 6
WIDE_COUNT = 7
WIDE_ROWS = 8
# a ray's BVH-walk stack (int32 entries, caller-owned scratch): [0, MESH_STACK_BASE) for the
# scene BVH (a wide walk pushes at most (WIDE - 1) * bvh.MAX_DEPTH + 1 = 421 entries, the
# ordered binary walk two per waiting node, 2 * (bvh.MAX_DEPTH + 1) = 122), the
# rest for a mesh's own binary BVH (at most MAX_DEPTH + 1)
MESH_STACK_BASE = 448
BVH_STACK = 512
# mesh BVH node rows (GeometryArrays.mesh_nodes): lower corner 0:3, upper corner 3:6, link 6:8
MESH_NODE_LO = 0
MESH_NODE_HI = 3
MESH_NODE_OFFSET = 6
MESH_NODE_COUNT = 7
MESH_NODE_WIDTH = 8

# the addresses in a mesh_info row from MESH_EMBREE (k of each, two int32 columns apiece)
EMBREE_ALL = 0  # the mesh's every triangle: nearest hits, shadows through a material override
EMBREE_OPAQUE = 1  # its triangles whose own material is opaque (0 when none)
EMBREE_CLEAR = 2  # the transparent ones (0 when none)
EMBREE_INTERSECT = 3  # address of rtcIntersect1
EMBREE_OCCLUDED = 4  # address of rtcOccluded1
N_EMBREE = 5


class GeometryArrays(NamedTuple):
    """Everything a ray needs to find what it hits (all NumPy arrays, read-only in kernels).

    Kept to few arrays on purpose: kernels pass this tuple to each other, and every array in
    it costs at every call that is not inlined (14 unused arrays measured at -14 %)."""

    prim_info: np.ndarray  # (P, N_PRIM_INFO) int32
    prim_params: np.ndarray  # (P, N_PRIM_PARAMS) float64
    xforms: np.ndarray  # (X, 3, 4) float64 world-to-object affine matrices
    node_box: np.ndarray  # (M, 2, 3) float64 scene BVH over the bounded analytic primitives
    node_link: np.ndarray  # (M, 2) int32
    node_wide: np.ndarray  # (W, WIDE_ROWS, WIDE) float32 the same BVH in eight-wide nodes
    node_prims: np.ndarray  # (N,) int32 primitive indices in leaf order
    # (3, 3) float64 rotation from world space into the frame node_box and node_wide are
    # built in, or (0, 3) when they are in world space (compile/bvh_frame.py): the walks
    # turn the ray for the box tests only
    bvh_frame: np.ndarray
    # (U,) primitives outside the BVH (infinite planes): int32, or int64 in scenes with tori
    # or CSG objects, which selects kernels compiled with those shapes (features.py)
    unbounded: np.ndarray
    # triangle meshes, each stored once in its own space with its own BVH (the bottom level);
    # SHAPE_MESH primitives instance them (their xform maps world to mesh space). The
    # instances have a top-level BVH of their own, walked after the analytic shapes'; its
    # boxes are float32 (and empty) in scenes without instances, which selects kernels
    # compiled without the instance walks (features.py).
    inst_box: np.ndarray  # (I, 2, 3) float64
    inst_link: np.ndarray  # (I, 2) int32
    inst_prims: np.ndarray  # (J,) int32 SHAPE_MESH primitive indices in leaf order
    mesh_info: np.ndarray  # (K, N_MESH_INFO) int32 (with Embree's addresses: MESH_EMBREE)
    mesh_vertices: np.ndarray  # (V, 3) float32 positions
    mesh_faces: np.ndarray  # (T, 3) int32 rows of mesh_vertices, counter-clockwise = front
    tri_material: np.ndarray  # (T,) int32 material row of each triangle
    tri_normals: np.ndarray  # (Tn, 3, 3) float32 corner normals of smooth-shaded triangles
    tri_uvs: np.ndarray  # (Tu, 3, 2) float32 corner texture coordinates
    # bottom-level nodes, one 32-byte row each (a box test and the node's link read one cache
    # line): columns MESH_NODE_LO, MESH_NODE_HI of mesh_nodes are the box (float32, rounded
    # outward); columns MESH_NODE_LINK of mesh_node_ints, an int32 view of the same memory,
    # the (offset, count) link (leaf offsets index mesh_node_tris)
    mesh_nodes: np.ndarray  # (N, 8) float32
    mesh_node_ints: np.ndarray  # (N, 8) int32, the same memory
    mesh_node_tris: np.ndarray  # (T,) int32 triangle indices in leaf order
    # (T, 3, 3) float32 corners of the triangles in leaf order (entry j: mesh_node_tris[j]):
    # the walks read a leaf's triangles from consecutive memory, not through two indirections
    mesh_leaf_corners: np.ndarray
    # textures (see texture_layout.py): one row per texture, all image texels in one array
    tex_info: np.ndarray  # (X, N_TEX_PARAMS) float64
    tex_pixels: np.ndarray  # (P,) float32 linear RGB


# photon map (LightArrays.photons rows, float32): where a photon landed, the power it
# carries (per channel) and its unit direction of travel, and the progressive pass it
# belongs to
PHOTON_POSITION = 0
PHOTON_POWER = 3
PHOTON_DIRECTION = 6
PHOTON_PASS = 9
PHOTON_WIDTH = 10
# photon grid scalars (LightArrays.photon_grid, float64), then per pass its squared radius
# at GRID_PASS + 2 p and its estimator's normalisation at GRID_PASS + 2 p + 1
GRID_INV_CELL = 0  # 1 / cell side (the side is the largest gather radius)
GRID_BITS = 1  # bits of each cell coordinate in the hash (kernels/caustics.py's cell_hash)
GRID_R2_MAX = 2  # the largest squared radius (pass 0's)
GRID_PASSES = 3
GRID_PASS = 4
_NO_PHOTONS = np.zeros((0, PHOTON_WIDTH), np.float32)
_NO_CELLS = np.zeros(1, np.int32)
_NO_GRID = np.zeros(GRID_PASS, np.float64)
_NO_MATS = np.zeros((0, N_MAT_PARAMS), np.float64)


class LightArrays(NamedTuple):
    """The lights (ambient ones excluded), the light buffers of the point lights and the
    caustics' photon map.

    A light buffer (see light_buffer.py) divides the directions leaving a point light into the
    cells of a cube map, LIGHT_BUFFER_RES x LIGHT_BUFFER_RES per face, and lists for each cell
    the analytic primitives that could block a shadow ray travelling through it, then the
    instance BVH's leaves it could meet: a shadow ray tests those instead of walking the BVHs.

    The photon map (compile/photon_map.py, docs/caustics.md) is empty in renders without
    caustics, and its ``photon_grid`` holds no pass: the render kernel skips its gather
    (kernels/caustics.py ``caustics_on``). With caustics, ``photons`` are sorted by the hash
    of their grid cell, ``photon_cells[h]:photon_cells[h + 1]`` being the photons of hash
    ``h``, and
    ``shadow_materials`` is the material table shadow rays see: the clear bodies'
    materials (bounded, kt > 0) pass all the light, as if the bodies were not there; the
    caustic and shadow photons add and take away what the bodies do to it
    (compile/photon_map.py shadow_material_table)."""

    table: np.ndarray  # (L, N_LIGHT_PARAMS) float64
    buffer_cells: np.ndarray  # (C, 3) int32: CELL_FIRST, CELL_COUNT, CELL_OPAQUE
    # (N,) int32 primitive indices, and -1 - node for a leaf of the instance BVH
    buffer_prims: np.ndarray
    photons: np.ndarray = _NO_PHOTONS  # (N, PHOTON_WIDTH) float32
    photon_cells: np.ndarray = _NO_CELLS  # (H + 1,) int32
    photon_grid: np.ndarray = _NO_GRID  # (GRID_PASS + 2 passes,) float64
    shadow_materials: np.ndarray = _NO_MATS  # (M, N_MAT_PARAMS) float64


class RenderParams(NamedTuple):
    """Scalars of one render (every field always has the same type, so one compiled kernel)."""

    width: int
    height: int
    samples: int
    max_depth: int
    min_weight: float
    epsilon: float
    seed: int
    ambient: tuple[float, float, float]  # sum of ambient lights (colour x intensity)
    background_top: tuple[float, float, float]
    background_bottom: tuple[float, float, float]
    camera_origin: tuple[float, float, float]
    camera_right: tuple[float, float, float]  # scaled by the half width of the image plane
    camera_up: tuple[float, float, float]  # scaled by the half height
    camera_forward: tuple[float, float, float]
    orthographic: int
    # focal blur: the lens's half axes (unit right and up times its radius; zero: a pinhole)
    # and the distance along camera_forward of the plane in focus (0: no focal blur)
    lens_u: tuple[float, float, float]
    lens_v: tuple[float, float, float]
    focal_distance: float
