"""Triangle meshes through the real pipeline: watertightness, instancing, smooth normals,
barycentric texture coordinates, per-triangle materials, degenerate triangles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

import whitted
from meshgen import cube, uv_sphere
from whitted.compile.embree import embree_library
from whitted.compile.scene import compile_scene
from whitted.kernels.accel import closest_hit, surface_normals
from whitted.kernels.layout import BVH_STACK, PRIM_MATERIAL
from whitted.kernels.uv import surface_uv


@njit(cache=False)
def _first_hits(geo, origins, directions, tmin, stack):
    """t of the nearest hit beyond tmin[k] for every ray (inf on a miss)."""
    out = np.empty(origins.shape[0])
    for k in range(origins.shape[0]):
        o = (origins[k, 0], origins[k, 1], origins[k, 2])
        d = (directions[k, 0], directions[k, 1], directions[k, 2])
        t, prim, tri, b1, b2 = closest_hit(geo, o, d, tmin[k], np.inf, stack)
        out[k] = t if prim >= 0 else np.inf
    return out


def _hits(compiled, origins, directions, tmin=None):
    origins = np.ascontiguousarray(origins, np.float64)
    directions = np.ascontiguousarray(directions, np.float64)
    if tmin is None:
        tmin = np.zeros(len(origins))
    return _first_hits(compiled.geometry, origins, directions,
                       np.ascontiguousarray(tmin, np.float64), np.empty(BVH_STACK, np.int32))


def _targets(verts, faces):
    """The exact places rays slip through leaky meshes: every vertex and edge midpoint."""
    v = verts.astype(np.float32).astype(np.float64)
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    mid = 0.5 * (v[edges[:, 0]] + v[edges[:, 1]])
    return np.concatenate([v, mid])


# every mesh test runs every way a mesh can be stored and traced: flattened into the scene BVH
# as triangle primitives (a small mesh used once), and instanced (stored once) with whitted's
# own mesh BVH or with Embree's (compile/embree.py; skipped where Embree does not load)
EMBREE = pytest.mark.skipif(embree_library() is None, reason="Embree not installed")
LAYOUTS = [pytest.param(None, id="flattened"), pytest.param("whitted", id="instanced"),
           pytest.param("embree", id="embree", marks=EMBREE)]


def compile_as(scene, layout):
    if layout is None:
        return compile_scene(scene)
    return compile_scene(scene, flatten_limit=0, mesh_tracer=layout)


TRANSFORMS = [
    None,
    whitted.Transform(scale=(1.7, 0.6, 1.1), rotate=(23.0, -41.0, 7.0), translate=(0.3, -2, 5)),
]


@pytest.fixture(scope="module")
def sphere_mesh():
    v, f = uv_sphere(24, 48)
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    assert (np.einsum("ij,ij->i", n, v[f].mean(axis=1)) > 0).all()  # wound outward
    return v, f


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("transform", TRANSFORMS, ids=["identity", "affine"])
def test_closed_mesh_is_watertight(sphere_mesh, transform, layout):
    """A ray from inside a closed mesh always hits it, and a ray that enters from outside
    always leaves: aimed exactly at every vertex and edge midpoint, and a million random."""
    v, f = sphere_mesh
    mesh = whitted.Mesh(v, f, transform=transform)
    compiled = compile_as(whitted.Scene(objects=[mesh]), layout)
    m = transform.matrix() if transform is not None else np.eye(4)

    def world(p):
        return p @ m[:3, :3].T + m[:3, 3]

    rng = np.random.default_rng(7)
    targets = _targets(v, f)
    inner = rng.uniform(-0.3, 0.3, (len(targets), 3))
    # inside -> out through each vertex / edge midpoint
    o, tgt = world(inner), world(targets)
    assert np.isfinite(_hits(compiled, o, tgt - o)).all()
    # outside -> in through each vertex / edge midpoint, then out again
    far = world(inner + 3.0 * (targets - inner))
    d = world(inner) - far
    t_in = _hits(compiled, far, d)
    assert np.isfinite(t_in).all()
    t_out = _hits(compiled, far, d, t_in * (1 + 1e-9))
    if layout == "embree":
        # Embree's robust mode is watertight along edges, not always at a vertex that many
        # triangles share: 3 of these sphere's 1,106 vertices let a ray aimed exactly at
        # them in from outside (without robust mode: 626 of the 7,730 targets)
        vertex = np.arange(len(targets)) < len(v)
        assert np.isfinite(t_out[~vertex]).all()
        assert (~np.isfinite(t_out[vertex])).sum() <= 0.005 * len(v)
    else:
        assert np.isfinite(t_out).all()
    # a million random rays from random interior points in random directions
    n = 1_000_000
    o = world(rng.uniform(-0.5, 0.5, (n, 3)))
    d = rng.normal(size=(n, 3))
    assert np.isfinite(_hits(compiled, o, d)).all()


@pytest.mark.parametrize("layout", LAYOUTS)
def test_mesh_hits_match_analytic_box(layout):
    """A box as 12 triangles gives the same distances and normals as the analytic box."""
    v, f = cube((-1, -0.5, -2), (1.5, 1, 0.5))
    rng = np.random.default_rng(3)
    o = rng.uniform(-6, 6, (2000, 3))
    d = rng.uniform((-1.5, -1, -2.5), (2, 1.5, 1), (2000, 3)) - o  # at the box and around it
    as_mesh = _hits(compile_as(whitted.Scene(objects=[whitted.Mesh(v, f)]), layout), o, d)
    as_box = _hits(compile_scene(whitted.Scene(objects=[
        whitted.Box(min=(-1, -0.5, -2), max=(1.5, 1, 0.5))])), o, d)
    assert 1000 < np.isfinite(as_box).sum() < 2000
    np.testing.assert_array_equal(np.isfinite(as_mesh), np.isfinite(as_box))
    hit = np.isfinite(as_box)
    exact = 1e-12 if layout != "embree" else 1e-6  # Embree traces in float32
    np.testing.assert_allclose(as_mesh[hit], as_box[hit], rtol=exact, atol=exact)


def test_instances_share_one_copy():
    v, f = uv_sphere(8, 16)
    base = whitted.Mesh(v, f)
    moved = base.model_copy(update={"transform": whitted.Transform(translate=(3, 0, 0))})
    scaled = base.model_copy(update={"transform": whitted.Transform(scale=2, translate=(-4, 0, 0))})
    compiled = compile_scene(whitted.Scene(objects=[base, moved, scaled]), flatten_limit=0)
    geo = compiled.geometry
    assert len(geo.mesh_faces) == len(f)  # the triangles are stored once
    assert len(geo.mesh_info) == 1
    assert compiled.triangles == len(f)
    assert compiled.instanced_triangles == 3 * len(f)
    # each instance is where its transform puts it: rays down -z through their centres
    o = np.array([[0, 0, 10], [3, 0, 10], [-4, 0, 10]], float)
    d = np.tile([0.0, 0.0, -1.0], (3, 1))
    np.testing.assert_allclose(_hits(compiled, o, d), [9.0, 9.0, 8.0], atol=1e-6)


def test_same_model_file_is_instanced(tmp_path):
    v, f = cube()
    lines = [f"v {x} {y} {z}" for x, y, z in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
    (tmp_path / "box.obj").write_text("\n".join(lines) + "\n")
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(
        '[[objects]]\ntype = "mesh"\nfile = "box.obj"\n\n'
        '[[objects]]\ntype = "mesh"\nfile = "box.obj"\ntransform = { translate = [4, 0, 0] }\n'
    )
    compiled = compile_scene(whitted.load_scene(scene_file), flatten_limit=0)
    assert len(compiled.geometry.mesh_faces) == 12
    assert compiled.instanced_triangles == 24


def _one_triangle_hit(mesh, ray_o, ray_d, layout):
    compiled = compile_as(whitted.Scene(objects=[mesh]), layout)
    geo = compiled.geometry
    t, prim, tri, b1, b2 = closest_hit(geo, ray_o, ray_d, 0.0, math.inf,
                                       np.empty(BVH_STACK, np.int32))
    assert prim == 0 and tri == (-1 if layout is None else 0)
    p = tuple(o + t * d for o, d in zip(ray_o, ray_d, strict=True))
    return geo, prim, tri, b1, b2, p


@pytest.mark.parametrize("layout", LAYOUTS)
def test_smooth_normals_interpolate_the_corners(layout):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    normals = np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1]], float) / [[1], [math.sqrt(2)],
                                                                      [math.sqrt(2)]]
    mesh = whitted.Mesh(v, [[0, 1, 2]], normals=normals)
    geo, prim, tri, b1, b2, p = _one_triangle_hit(mesh, (0.25, 0.5, 1.0), (0.0, 0.0, -1.0),
                                                  layout)
    if tri >= 0:
        assert (b1, b2) == pytest.approx((0.25, 0.5), rel=1e-6)
    ng, ns = surface_normals(geo, prim, tri, b1, b2, p)
    assert ng == pytest.approx((0, 0, 1))
    expect = 0.25 * normals[0] + 0.25 * normals[1] + 0.5 * normals[2]
    assert ns == pytest.approx(tuple(expect / np.linalg.norm(expect)))
    # smooth = false ignores the normals
    flat = whitted.Mesh(v, [[0, 1, 2]], normals=normals, smooth=False)
    geo, prim, tri, b1, b2, p = _one_triangle_hit(flat, (0.25, 0.5, 1.0), (0.0, 0.0, -1.0),
                                                  layout)
    assert surface_normals(geo, prim, tri, b1, b2, p)[1] == pytest.approx((0, 0, 1))


@pytest.mark.parametrize("layout", LAYOUTS[1:])
def test_normals_of_a_transformed_instance_flat_and_smooth(layout):
    """An instance turned, scaled unevenly and moved: its normals in world space are the
    mesh's own mapped by the inverse transpose and normalised; a flat mesh's shading normal
    is its geometric one (mapped once), a smooth one's the corners' blend, mapped."""
    transform = TRANSFORMS[1]
    m = transform.matrix()[:3, :3]
    to_world = np.linalg.inv(m).T
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    normals = np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1]], float) / [[1], [math.sqrt(2)],
                                                                      [math.sqrt(2)]]
    local_hit = np.array([0.25, 0.5, 0.0])
    world_hit = m @ local_hit + transform.matrix()[:3, 3]
    n_world = to_world @ [0.0, 0.0, 1.0]
    n_world /= np.linalg.norm(n_world)
    ray_o = tuple(world_hit + 2.0 * n_world)
    ray_d = tuple(-n_world)
    for smooth in (False, True):
        mesh = whitted.Mesh(v, [[0, 1, 2]], normals=normals, smooth=smooth, transform=transform)
        geo, prim, tri, b1, b2, p = _one_triangle_hit(mesh, ray_o, ray_d, layout)
        assert p == pytest.approx(tuple(world_hit), abs=1e-6)
        ng, ns = surface_normals(geo, prim, tri, b1, b2, p)
        assert ng == pytest.approx(tuple(n_world), abs=1e-6)
        if not smooth:
            assert ns == ng
            continue
        blend = to_world @ (0.25 * normals[0] + 0.25 * normals[1] + 0.5 * normals[2])
        assert ns == pytest.approx(tuple(blend / np.linalg.norm(blend)), abs=1e-6)
        assert abs(np.dot(ns, ng)) < 0.999  # a different direction from the geometric one


@pytest.mark.parametrize("layout", LAYOUTS)
def test_computed_smooth_normals_respect_the_crease_angle(layout):
    v, f = cube()
    sharp = compile_as(whitted.Scene(objects=[whitted.Mesh(v, f, smooth=True)]), layout)
    # 90-degree edges are above the default 60-degree crease: every corner keeps its face normal
    n = sharp.geometry.tri_normals
    face = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    face /= np.linalg.norm(face, axis=1, keepdims=True)
    np.testing.assert_allclose(n, np.repeat(face[:, None, :], 3, axis=1), atol=1e-6)
    soft = compile_as(whitted.Scene(objects=[whitted.Mesh(v, f, smooth=True, crease_angle=100)]),
                      layout)
    # above 90 degrees everything joins: a corner normal points along the corner's diagonal
    corner = soft.geometry.tri_normals.reshape(-1, 3)
    np.testing.assert_allclose(np.abs(corner), 1 / math.sqrt(3), atol=1e-6)
    # a sphere mesh smooths towards the true sphere normal
    sv, sf = uv_sphere(16, 32)
    smooth = compile_as(whitted.Scene(objects=[whitted.Mesh(sv, sf, smooth=True)]), layout)
    at = sv[sf].astype(np.float32).astype(np.float64)
    true = at / np.linalg.norm(at, axis=2, keepdims=True)
    assert np.max(np.abs(smooth.geometry.tri_normals - true)) < 0.02


@pytest.mark.parametrize("layout", LAYOUTS)
def test_mesh_uvs_and_barycentric_default(layout):
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], float)
    uvs = np.array([[0.1, 0.2], [0.9, 0.2], [0.1, 0.8]])
    geo, prim, tri, b1, b2, p = _one_triangle_hit(whitted.Mesh(v, [[0, 1, 2]], uvs=uvs),
                                                  (0.5, 1.0, 1.0), (0.0, 0.0, -1.0), layout)
    u, w = surface_uv(geo, prim, tri, b1, b2, p)
    assert (u, w) == pytest.approx((0.1 + 0.8 * 0.25, 0.2 + 0.6 * 0.5))
    geo, prim, tri, b1, b2, p = _one_triangle_hit(whitted.Mesh(v, [[0, 1, 2]]),
                                                  (0.5, 1.0, 1.0), (0.0, 0.0, -1.0), layout)
    assert surface_uv(geo, prim, tri, b1, b2, p) == pytest.approx((0.25, 0.5))


@pytest.mark.parametrize("layout", LAYOUTS)
def test_degenerate_triangles_are_dropped_with_a_count(layout):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], float)
    faces = [[0, 1, 2], [0, 1, 3], [1, 1, 2], [0, 2, 1]]  # collinear, repeated corner
    compiled = compile_as(whitted.Scene(objects=[whitted.Mesh(v, faces)]), layout)
    assert compiled.triangles == 2
    assert any("dropped 2 degenerate triangles" in w for w in compiled.warnings)


def test_per_triangle_materials_and_override():
    """Two triangles of one mesh with different materials shade differently; an object's
    material overrides them all."""
    v = np.array([[-2, -1, 0], [0, -1, 0], [0, 1, 0], [-2, 1, 0], [2, -1, 0], [2, 1, 0]], float)
    faces = [[0, 1, 2], [0, 2, 3], [1, 4, 5], [1, 5, 2]]
    from whitted.compile.meshes import MeshSource
    mesh = whitted.Mesh(v, faces)
    scene = whitted.Scene(objects=[mesh], lights=[whitted.AmbientLight(intensity=1.0)])
    scene.camera.position = (0.0, 0.0, 5.0)
    # through the public path: default material everywhere
    img = whitted.render(scene, width=40, height=20).pixels
    assert img[10, 12] == pytest.approx(img[10, 28])
    # two file materials through the compiler's mesh source
    red = whitted.Material(color=(1, 0, 0), ka=1, kd=0)
    blue = whitted.Material(color=(0, 0, 1), ka=1, kd=0)
    src = MeshSource("two.obj", v, np.array(faces), None, None, np.array([0, 0, 1, 1]),
                     [red, blue])
    from whitted.compile import scene as compile_module

    original = compile_module.mesh_source
    compile_module.mesh_source = lambda *a: src
    try:
        compiled = compile_scene(scene, flatten_limit=0)  # instanced: the triangles' materials
        mats = compiled.materials[compiled.geometry.tri_material]
        assert (mats[:2, 0] == 1).all() and (mats[2:, 2] == 1).all()
        compiled = compile_scene(scene)  # flattened: each triangle primitive has its own
        mats = compiled.materials[compiled.geometry.prim_info[:, PRIM_MATERIAL]]
        assert (mats[:2, 0] == 1).all() and (mats[2:, 2] == 1).all()
        over = scene.model_copy(update={"objects": [mesh.model_copy(update={
            "material": whitted.Material(color=(0, 1, 0), ka=1, kd=0)})]})
        compiled = compile_scene(over, flatten_limit=0)
        assert compiled.geometry.prim_info[0, PRIM_MATERIAL] >= 0
        flat = compile_scene(over)
        green = flat.materials[flat.geometry.prim_info[:, PRIM_MATERIAL]]
        assert (green[:, 1] == 1).all() and (green[:, 0] == 0).all()
    finally:
        compile_module.mesh_source = original


def test_closed_mesh_rendered_from_inside_and_outside():
    """From inside a closed mesh every pixel sees the mesh (nothing leaks to the background);
    from outside its silhouette is the sphere's."""
    v, f = uv_sphere(32, 64, r=2.0)
    mesh = whitted.Mesh(v, f, smooth=True, material=whitted.Material(color=(1, 1, 1), ka=1))
    scene = whitted.Scene(objects=[mesh], lights=[whitted.PointLight(position=(0, 0.5, 0))],
                          background=whitted.Background(color=(0, 0, 0)))
    scene.camera.position = (0.0, 0.0, 0.3)
    depth = whitted.render_aovs(scene, width=160, height=120)["depth"]
    assert np.isfinite(depth).all()
    img = whitted.render(scene, width=64, height=48).pixels
    assert img.min() > 0.05  # lit or ambient everywhere, never background black
    scene.camera.position = (0.0, 0.0, 8.0)
    scene.camera.fov = 40.0
    depth = whitted.render_aovs(scene, width=101, height=101)["depth"]
    analytic = whitted.render_aovs(scene.model_copy(update={"objects": [whitted.Sphere(
        radius=2.0)]}), width=101, height=101)["depth"]
    differ = np.isfinite(depth) != np.isfinite(analytic)
    assert differ.sum() <= 0.03 * np.isfinite(analytic).sum()  # facets cut a thin rim only


def test_small_meshes_are_flattened_big_ones_instanced():
    """A mesh joins the scene BVH as triangles while all its copies stay within the limit; past
    it the mesh is stored once and instanced."""
    v, f = uv_sphere(4, 8)  # 48 triangles
    assert len(f) == 48
    base = whitted.Mesh(v, f)
    copies = [base.model_copy(update={"transform": whitted.Transform(translate=(3 * k, 0, 0))})
              for k in range(3)]
    two = compile_scene(whitted.Scene(objects=copies[:2]), flatten_limit=100)
    assert len(two.geometry.mesh_faces) == 0 and len(two.geometry.prim_info) == 96
    assert two.geometry.inst_box.dtype == np.float32  # the kernels without instances
    three = compile_scene(whitted.Scene(objects=copies), flatten_limit=100)
    assert len(three.geometry.mesh_faces) == 48 and len(three.geometry.prim_info) == 3
    assert three.instanced_triangles == two.instanced_triangles + 48 == 144
    # both layouts see the same surfaces
    rng = np.random.default_rng(5)
    o = np.tile([3.0, 0.5, 9.0], (4000, 1))
    d = rng.uniform((-6, -1.5, -9), (6, 1.5, -9), (4000, 3)) - [0.0, 0.5, 0.0]
    t_flat, t_inst = _hits(two, o, d), _hits(compile_scene(
        whitted.Scene(objects=copies[:2]), flatten_limit=0), o, d)
    assert np.isfinite(t_flat).sum() > 500
    np.testing.assert_array_equal(np.isfinite(t_flat), np.isfinite(t_inst))
    hit = np.isfinite(t_flat)
    np.testing.assert_allclose(t_flat[hit], t_inst[hit], rtol=1e-6)


def test_mesh_nodes_are_sibling_pairs_on_cache_lines():
    """Two different meshes (so two node blocks): every interior node's children sit side by
    side on one 64-byte line, each child's box lies inside its parent's, and the leaves list
    every triangle of their mesh exactly once; the int32 link columns share the rows' memory."""
    v1, f1 = uv_sphere(12, 24)
    v2, f2 = cube()
    scene = whitted.Scene(objects=[whitted.Mesh(v1, f1), whitted.Mesh(v2, f2)])
    geo = compile_scene(scene, flatten_limit=0, mesh_tracer="whitted").geometry
    nodes, ints = geo.mesh_nodes, geo.mesh_node_ints
    assert nodes.shape[1] == 8 and nodes.dtype == np.float32 and ints.dtype == np.int32
    assert np.shares_memory(nodes, ints)
    assert nodes.ctypes.data % 64 == 0
    assert len(geo.mesh_info) == 2
    for mesh, tri_count in enumerate((len(f1), len(f2))):
        root = int(geo.mesh_info[mesh, 0])
        tri_offset = int(geo.mesh_info[mesh, 1])
        assert root % 2 == 0
        seen = []
        stack = [root]
        while stack:
            node = stack.pop()
            count = int(ints[node, 7])
            if count > 0:
                first = int(ints[node, 6])
                seen.extend(range(first, first + count))
                continue
            first = int(ints[node, 6])
            assert first % 2 == 0 and first > root  # the pair fills one cache line
            for child in (first, first + 1):
                assert np.all(nodes[child, :3] >= nodes[node, :3])
                assert np.all(nodes[child, 3:6] <= nodes[node, 3:6])
                stack.append(child)
        entries = np.sort(np.array(seen))
        np.testing.assert_array_equal(entries, tri_offset + np.arange(tri_count))
        tris = np.sort(geo.mesh_node_tris[entries])
        np.testing.assert_array_equal(tris, tri_offset + np.arange(tri_count))
        # the padding row after the root holds an empty box: no ray can enter it
        assert np.all(nodes[root + 1, :3] > nodes[root + 1, 3:6])
