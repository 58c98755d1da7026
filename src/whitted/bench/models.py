"""The benchmark scenes' triangle models, generated deterministically.

The four cones of the coursework's scene (642 triangles together) are small and committed in
``benchmarks/models/``; :func:`write_cones` wrote them. The ice block, the water inside it and
the air bubble (001's subject, every object a mesh), the million-triangle height field and the
mesh benchmarks' models (a bumpy UV sphere, the Stanford bunny subdivided, a finely revolved
vase of long thin triangles, a bumpy torus placed 100 times) are generated on first use into
the bench cache folder (see :func:`generated_model`). ``whitted bench --quick`` renders the
same scenes with small versions of the big models (``quick-NAME``, see ``QUICK``).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

#: segments of the four cones: 2 triangles per segment (side + base) = 642 triangles in all
CONE_SEGMENTS = (96, 80, 80, 65)
HEIGHT_FIELD_QUADS = (1000, 500)  # 1,000,000 triangles
SPHERE_GRID = (1000, 501)  # longitudes, latitude bands: 2·1000·500 = 1,000,000 triangles
VASE_GRID = (20_000, 24)  # revolutions steps, profile segments: 980,000 long thin triangles
TORUS_GRID = (250, 200)  # 100,000 triangles, placed 100 times
BUNNY_SUBDIVISIONS = 2  # 69,451 · 4² = 1,111,216 triangles
BUNNY_FILE = "stanford-bunny/stanford-bunny.obj"  # in the shared OBJ corpus (see below)


def bench_cache_dir() -> Path:
    """Where generated benchmark models live: ``$WHITTED_CACHE_DIR/bench`` (default
    ``~/.cache/whitted/bench``)."""
    base = os.environ.get("WHITTED_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "whitted"
    )
    return Path(base) / "bench"


def cone_mesh(segments: int) -> tuple[np.ndarray, np.ndarray]:
    """A cone of radius 1 and height 1 standing on the origin: apex (0, 1, 0), a base disk in
    y = 0; ``segments`` side triangles and as many base triangles, outward facing."""
    angles = np.arange(segments) * (2 * np.pi / segments)
    ring = np.stack([np.cos(angles), np.zeros(segments), -np.sin(angles)], axis=1)
    vertices = np.vstack([[[0.0, 1.0, 0.0], [0.0, 0.0, 0.0]], ring])
    i = np.arange(segments)
    a, b = 2 + i, 2 + (i + 1) % segments
    side = np.stack([a, b, np.zeros(segments, np.int64)], axis=1)
    base = np.stack([np.ones(segments, np.int64), b, a], axis=1)
    return vertices, np.vstack([side, base])


def rounded_box_mesh(
    half_extents: tuple[float, float, float], radius: float, divisions: int
) -> tuple[np.ndarray, np.ndarray]:
    """A box with rounded edges and corners centred on the origin (a sphere when the radius
    equals every half extent): a cube's faces split into ``divisions``² quads, each point
    pushed onto the rounded surface. 12·divisions² triangles, outward facing."""
    s = np.linspace(-1.0, 1.0, divisions + 1)
    grid_s, grid_t = np.meshgrid(s, s, indexing="ij")
    points, faces = [], []
    for normal in np.vstack([np.eye(3), -np.eye(3)]):
        a = np.roll(np.abs(normal), 1)
        b = np.cross(normal, a)  # a x b = normal: quads wind counter-clockwise seen from out
        face_points = normal + grid_s[..., None] * a + grid_t[..., None] * b
        base = sum(len(p) for p in points)
        points.append(face_points.reshape(-1, 3))
        n = divisions + 1
        i, j = np.meshgrid(np.arange(divisions), np.arange(divisions), indexing="ij")
        v00 = base + i * n + j
        v10, v11, v01 = v00 + n, v00 + n + 1, v00 + 1
        quads = np.stack([v00, v10, v11, v01], axis=-1).reshape(-1, 4)
        faces.append(np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]))
    cube = np.vstack(points)
    tri = np.vstack(faces)
    # weld the points the faces share along the cube's edges
    _, first, inverse = np.unique(np.round(cube, 9), axis=0, return_index=True,
                                  return_inverse=True)
    order = np.argsort(first)
    remap = np.empty_like(order)
    remap[order] = np.arange(len(order))
    cube = cube[first[order]]
    tri = remap[inverse.reshape(-1)][tri]
    half = np.asarray(half_extents, dtype=np.float64)
    q = cube * half
    inner = np.clip(q, -(half - radius), half - radius)
    offset = q - inner
    length = np.linalg.norm(offset, axis=1, keepdims=True)
    vertices = inner + radius * offset / length
    # keep the winding outward whatever the axis order above produced
    a, b, c = (vertices[tri[:, k]] for k in range(3))
    centre = (a + b + c) / 3
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), centre) < 0
    tri[inward] = tri[inward][:, [0, 2, 1]]
    return vertices, tri


def height_field_mesh(quads: tuple[int, int] = HEIGHT_FIELD_QUADS,
                      size: tuple[float, float] = (16.0, 8.0)) -> tuple[np.ndarray, np.ndarray]:
    """Rolling hills over x in ±size[0]/2, z in ±size[1]/2: 2·quads[0]·quads[1] triangles,
    facing up."""
    nx, nz = quads
    x = np.linspace(-size[0] / 2, size[0] / 2, nx + 1)
    z = np.linspace(-size[1] / 2, size[1] / 2, nz + 1)
    gx, gz = np.meshgrid(x, z, indexing="ij")
    height = (0.45 * np.sin(1.1 * gx + 0.3) * np.cos(0.9 * gz)
              + 0.25 * np.sin(2.3 * gx + 1.7 * gz)
              + 0.08 * np.cos(7.1 * gx - 5.3 * gz)
              + 0.03 * np.sin(23.0 * gx) * np.sin(19.0 * gz))
    vertices = np.stack([gx, height, gz], axis=-1).reshape(-1, 3)
    i, k = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
    v00 = i * (nz + 1) + k
    v10, v11, v01 = v00 + nz + 1, v00 + nz + 2, v00 + 1
    quad = np.stack([v00, v01, v11, v10], axis=-1).reshape(-1, 4)  # counter-clockwise from +y
    faces = np.vstack([quad[:, [0, 1, 2]], quad[:, [0, 2, 3]]])
    return vertices, faces


def _orient_outward(vertices: np.ndarray, tri: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Triangles wound counter-clockwise seen from outside a body star-shaped about
    ``centre``."""
    a, b, c = (vertices[tri[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), (a + b + c) / 3 - centre) < 0
    tri = tri.copy()
    tri[inward] = tri[inward][:, [0, 2, 1]]
    return tri


def displaced_sphere_mesh(grid: tuple[int, int] = SPHERE_GRID,
                          bumps: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """A closed UV sphere of radius about 1 with bumps of relative height ``bumps``:
    ``grid[0]`` longitudes, ``grid[1]`` latitude bands (triangle fans at the poles, quads
    between), 2·grid[0]·(grid[1] − 1) flat triangles, outward facing."""
    n_lon, n_lat = grid
    theta = np.linspace(0.0, np.pi, n_lat + 1)[1:-1]  # the rings between the poles
    phi = np.arange(n_lon) * (2 * np.pi / n_lon)
    gt, gp = np.meshgrid(theta, phi, indexing="ij")
    radius = 1.0 + bumps * (np.sin(7 * gp) * np.sin(5 * gt) + 0.5 * np.sin(23 * gp + 3 * gt)
                            * np.sin(17 * gt) + 0.25 * np.cos(61 * gp) * np.sin(53 * gt))
    ring = np.stack([radius * np.sin(gt) * np.cos(gp), radius * np.cos(gt),
                     -radius * np.sin(gt) * np.sin(gp)], axis=-1).reshape(-1, 3)
    vertices = np.vstack([[[0.0, 1.0, 0.0]], ring, [[0.0, -1.0, 0.0]]])
    rings = n_lat - 1
    j = np.arange(n_lon)
    j1 = (j + 1) % n_lon
    top = np.stack([np.zeros(n_lon, np.int64), 1 + j, 1 + j1], axis=1)
    bottom_index = len(vertices) - 1
    last = 1 + (rings - 1) * n_lon
    bottom = np.stack([np.full(n_lon, bottom_index), last + j1, last + j], axis=1)
    r, jj = np.meshgrid(np.arange(rings - 1), j, indexing="ij")
    v00 = 1 + r * n_lon + jj
    v01 = 1 + r * n_lon + (jj + 1) % n_lon
    v10, v11 = v00 + n_lon, v01 + n_lon
    quads = np.stack([v00, v10, v11, v01], axis=-1).reshape(-1, 4)
    tri = np.vstack([top, quads[:, [0, 1, 2]], quads[:, [0, 2, 3]], bottom])
    return vertices, _orient_outward(vertices, tri, np.zeros(3))


def vase_mesh(grid: tuple[int, int] = VASE_GRID) -> tuple[np.ndarray, np.ndarray]:
    """A vase turned on a lathe, as CAD tools tessellate one: a profile of ``grid[1]`` straight
    segments revolved in ``grid[0]`` fine steps, and a flat bottom as one fan, so every
    triangle is long and thin (about 400:1 on the sides, thousands to one in the bottom).
    2·grid[0]·grid[1] + grid[0] triangles, outward facing; open at the top."""
    steps, segments = grid
    s = np.linspace(0.0, 1.0, segments + 1)
    height = 2.0 * s
    radius = 0.55 + 0.35 * np.sin(np.pi * (1.25 * s + 0.1)) + 0.12 * s ** 3
    phi = np.arange(steps) * (2 * np.pi / steps)
    gr, gp = np.meshgrid(radius, phi, indexing="ij")
    ring = np.stack([gr * np.cos(gp), np.repeat(height[:, None], steps, axis=1),
                     -gr * np.sin(gp)], axis=-1).reshape(-1, 3)
    vertices = np.vstack([ring, [[0.0, 0.0, 0.0]]])
    k, j = np.meshgrid(np.arange(segments), np.arange(steps), indexing="ij")
    v00 = k * steps + j
    v01 = k * steps + (j + 1) % steps
    v10, v11 = v00 + steps, v01 + steps
    quads = np.stack([v00, v01, v11, v10], axis=-1).reshape(-1, 4)
    jj = np.arange(steps)
    bottom = np.stack([np.full(steps, len(vertices) - 1), (jj + 1) % steps, jj], axis=1)
    side = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    # sides face away from the axis, the bottom faces down
    a, b, c = (vertices[side[:, m]] for m in range(3))
    centre = (a + b + c) / 3
    outward = centre.copy()
    outward[:, 1] = 0.0
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), outward) < 0
    side[inward] = side[inward][:, [0, 2, 1]]
    a, b, c = (vertices[bottom[:, m]] for m in range(3))
    up = np.cross(b - a, c - a)[:, 1] > 0
    bottom[up] = bottom[up][:, [0, 2, 1]]
    return vertices, np.vstack([side, bottom])


def bumpy_torus_mesh(grid: tuple[int, int] = TORUS_GRID, major: float = 1.0,
                     minor: float = 0.38) -> tuple[np.ndarray, np.ndarray]:
    """A closed torus about the y axis with a bumpy tube: ``grid[0]`` steps around the ring,
    ``grid[1]`` around the tube, 2·grid[0]·grid[1] triangles, outward facing."""
    nu, nv = grid
    u = np.arange(nu) * (2 * np.pi / nu)
    v = np.arange(nv) * (2 * np.pi / nv)
    gu, gv = np.meshgrid(u, v, indexing="ij")
    r = minor * (1.0 + 0.12 * np.sin(9 * gu) * np.sin(5 * gv) + 0.05 * np.sin(31 * gu + 7 * gv))
    ring = major + r * np.cos(gv)
    vertices = np.stack([ring * np.cos(gu), r * np.sin(gv), -ring * np.sin(gu)],
                        axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    v00 = i * nv + j
    v01 = i * nv + (j + 1) % nv
    v10 = ((i + 1) % nu) * nv + j
    v11 = ((i + 1) % nu) * nv + (j + 1) % nv
    quads = np.stack([v00, v10, v11, v01], axis=-1).reshape(-1, 4)
    tri = np.vstack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    # outward: away from the tube's centre line
    a, b, c = (vertices[tri[:, k]] for k in range(3))
    centre = (a + b + c) / 3
    axis_point = centre.copy()
    axis_point[:, 1] = 0.0
    axis_point *= (major / np.maximum(np.linalg.norm(axis_point, axis=1), 1e-12))[:, None]
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), centre - axis_point) < 0
    tri[inward] = tri[inward][:, [0, 2, 1]]
    return vertices, tri


def subdivide(vertices: np.ndarray, faces: np.ndarray, levels: int = 1,
              roughness: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Each triangle split in four at its edge midpoints, ``levels`` times (shared edges share
    their midpoint, so a closed mesh stays closed). ``roughness`` > 0 then moves every new
    point along its vertex normal by up to that fraction of the mean edge length (a
    deterministic pattern), like the noise of a finer scan."""
    v = np.asarray(vertices, np.float64)
    f = np.asarray(faces, np.int64)
    original = len(v)
    for _ in range(levels):
        edges = np.sort(np.vstack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        mid = len(v) + inverse.reshape(3, -1)  # midpoint index of edge (01, 12, 20) per face
        v = np.vstack([v, 0.5 * (v[unique[:, 0]] + v[unique[:, 1]])])
        a, b, c = f[:, 0], f[:, 1], f[:, 2]
        ab, bc, ca = mid
        f = np.vstack([np.stack([a, ab, ca], 1), np.stack([ab, b, bc], 1),
                       np.stack([ca, bc, c], 1), np.stack([ab, bc, ca], 1)])
    if roughness > 0.0 and len(v) > original:
        p = v[f]
        face_n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        normals = np.zeros_like(v)
        for k in range(3):
            np.add.at(normals, f[:, k], face_n)
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
        edge = float(np.mean(np.linalg.norm(p[:, 1] - p[:, 0], axis=1)))
        k = np.arange(len(v) - original, dtype=np.float64)
        wobble = np.sin(k * 12.9898) * 43758.5453
        wobble = 2.0 * (wobble - np.floor(wobble)) - 1.0  # in [-1, 1), deterministic
        v[original:] += (roughness * edge * wobble)[:, None] * normals[original:]
    return v, f


def bunny_source() -> Path | None:
    """The Stanford bunny OBJ (69,451 triangles; Stanford 3D Scanning Repository, free to
    redistribute with credit, not committed here): ``$WHITTED_BUNNY_OBJ``, else the shared
    OBJ corpus ``shared/data/obj/`` beside the checkout (or any parent folder's); None if
    neither is there."""
    chosen = os.environ.get("WHITTED_BUNNY_OBJ")
    if chosen:
        return Path(chosen) if Path(chosen).is_file() else None
    for parent in Path(__file__).resolve().parents:
        for candidate in (parent / "shared" / "data" / "obj" / BUNNY_FILE,
                          parent / "data" / "obj" / BUNNY_FILE):
            if candidate.is_file():
                return candidate
    return None


class MissingSourceModel(FileNotFoundError):
    """A generated model needs a file that is not on this machine (the bunny)."""


def bunny_mesh(levels: int = BUNNY_SUBDIVISIONS) -> tuple[np.ndarray, np.ndarray]:
    """The Stanford bunny, subdivided ``levels`` times with scan-like roughness."""
    from ..assets.mesh import load_mesh

    source = bunny_source()
    if source is None:
        raise MissingSourceModel("the Stanford bunny is not on this machine: set "
                                 "WHITTED_BUNNY_OBJ to stanford-bunny.obj")
    mesh = load_mesh(source)
    return subdivide(mesh.vertices, mesh.faces, levels, roughness=0.3 if levels else 0.0)


def write_obj(path: Path, vertices: np.ndarray, faces: np.ndarray, comment: str = "") -> Path:
    lines = [f"# {line}" for line in comment.splitlines()]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces.tolist()]
    _write_atomically(path, ("\n".join(lines) + "\n").encode())
    return path


def write_ply(path: Path, vertices: np.ndarray, faces: np.ndarray) -> Path:
    """A binary little-endian PLY: float32 vertices, triangles as uchar count + int32 indices."""
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment generated by whitted bench\n"
        f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    ).encode()
    face_rows = np.empty(len(faces), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    face_rows["n"] = 3
    face_rows["v"] = faces
    body = vertices.astype("<f4").tobytes() + face_rows.tobytes()
    _write_atomically(path, header + body)
    return path


def _write_atomically(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def write_cones(folder: Path) -> list[Path]:
    """The coursework's four cones (642 triangles) as ``cone_<segments>.obj`` files."""
    paths = []
    for segments in sorted(set(CONE_SEGMENTS)):
        vertices, faces = cone_mesh(segments)
        paths.append(write_obj(folder / f"cone_{segments}.obj", vertices, faces,
                               f"cone: radius 1, height 1, {segments} segments, "
                               f"{len(faces)} triangles (whitted.bench.models.cone_mesh)"))
    return paths


def _ice_block(path: Path) -> Path:
    return write_obj(path, *rounded_box_mesh((1.2, 1.1, 1.2), 0.18, 24), "ice block")


def _water(path: Path) -> Path:
    return write_obj(path, *rounded_box_mesh((0.9, 0.8, 0.9), 0.3, 20), "water inside")


def _bubble(path: Path) -> Path:
    return write_obj(path, *rounded_box_mesh((0.3, 0.3, 0.3), 0.3, 12), "air bubble")


def _height_field(path: Path) -> Path:
    return write_ply(path, *height_field_mesh())


#: generated/<name> in a benchmark scene -> the function that writes it
GENERATORS: dict[str, Callable[[Path], Path]] = {
    "ice_block.obj": _ice_block,
    "water.obj": _water,
    "bubble.obj": _bubble,
    "height_field_1m.ply": _height_field,
    "sphere_1m.ply": lambda path: write_ply(path, *displaced_sphere_mesh()),
    "bunny_1m.ply": lambda path: write_ply(path, *bunny_mesh()),
    "vase_1m.ply": lambda path: write_ply(path, *vase_mesh()),
    "torus_100k.ply": lambda path: write_ply(path, *bumpy_torus_mesh()),
}

#: the small versions ``whitted bench --quick`` renders instead (``quick-<name>``)
QUICK: dict[str, Callable[[Path], Path]] = {
    "height_field_1m.ply": lambda path: write_ply(path, *height_field_mesh((100, 50))),
    "sphere_1m.ply": lambda path: write_ply(path, *displaced_sphere_mesh((100, 51))),
    "bunny_1m.ply": lambda path: write_ply(path, *bunny_mesh(0)),
    "vase_1m.ply": lambda path: write_ply(path, *vase_mesh((2000, 12))),
    "torus_100k.ply": lambda path: write_ply(path, *bumpy_torus_mesh((25, 20))),
}


def generated_model(name: str, folder: Path | None = None, quick: bool = False) -> Path:
    """The path of generated model ``name`` (its small version with ``quick``, where it has
    one), writing it first if it is not there yet."""
    if name not in GENERATORS:
        known = ", ".join(sorted(GENERATORS))
        raise KeyError(f"no generated model {name!r} (known: {known})")
    write = GENERATORS[name]
    if quick and name in QUICK:
        write, name = QUICK[name], f"quick-{name}"
    path = (folder or bench_cache_dir()) / name
    if not path.exists():
        write(path)
    return path
