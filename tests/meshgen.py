"""Closed test meshes made in NumPy (no files): a UV sphere with fans at the poles, a cube."""

from __future__ import annotations

import numpy as np


def uv_sphere(n_lat: int, n_lon: int, r: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """A closed, outward-wound UV sphere of radius ``r``: ``n_lon`` triangles meet at each pole
    (a vertex shared by many triangles), quads split in two elsewhere."""
    th = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    ph = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    t, p = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    verts = np.vstack([[0, 1, 0], ring, [0, -1, 0]]) * r
    faces = []

    def idx(i, j):
        return 1 + i * n_lon + (j % n_lon)

    for j in range(n_lon):
        faces.append([0, idx(0, j + 1), idx(0, j)])
    for i in range(n_lat - 2):
        for j in range(n_lon):
            a, b, c, d = idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1)
            faces += [[a, b, d], [a, d, c]]
    s = len(verts) - 1
    for j in range(n_lon):
        faces.append([s, idx(n_lat - 2, j), idx(n_lat - 2, j + 1)])
    return verts, np.array(faces)


def cube(lo=(-1.0, -1.0, -1.0), hi=(1.0, 1.0, 1.0)) -> tuple[np.ndarray, np.ndarray]:
    """An axis-aligned box as 12 outward-wound triangles over 8 shared corners."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]], float)
    quads = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]]
    f = [[q[0], q[1], q[2]] for q in quads] + [[q[0], q[2], q[3]] for q in quads]
    return v, np.array(f)
