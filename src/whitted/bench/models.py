"""The benchmark scenes' triangle models, generated deterministically.

The four cones of the coursework's scene (642 triangles together) are small and committed in
``benchmarks/models/``; :func:`write_cones` wrote them. The ice block, the water inside it and
the air bubble (001's subject, every object a mesh) and the million-triangle height field are
generated on first use into the bench cache folder (see :func:`generated_model`).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

#: segments of the four cones: 2 triangles per segment (side + base) = 642 triangles in all
CONE_SEGMENTS = (96, 80, 80, 65)
HEIGHT_FIELD_QUADS = (1000, 500)  # 1,000,000 triangles


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
}


def generated_model(name: str, folder: Path | None = None) -> Path:
    """The path of generated model ``name``, writing it first if it is not there yet."""
    if name not in GENERATORS:
        known = ", ".join(sorted(GENERATORS))
        raise KeyError(f"no generated model {name!r} (known: {known})")
    path = (folder or bench_cache_dir()) / name
    if not path.exists():
        GENERATORS[name](path)
    return path
