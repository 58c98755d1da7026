"""Smooth vertex normals with a crease angle, for meshes that come without normals.

Each corner of each triangle gets the average of the normals of the triangles around its
vertex whose normal is within the crease angle of its own triangle's, each weighted by the
triangle's angle at that vertex (so how a face happens to be split into triangles does not
bias the result): surfaces are
smooth across gentle edges and stay sharp across edges steeper than the crease angle (a cube
keeps its faces flat, a tessellated sphere turns round). Vertices are matched by position, so
files that repeat a vertex per face (STL) smooth as well.
"""

from __future__ import annotations

import numpy as np

from ..jit import builder
from ..jit.python_twins import for_size

#: meshes of at most this many triangles get their normals from the Python twin until the
#: builders are compiled (jit/python_twins.py)
PYTHON_LIMIT = 4096


@builder(_nrt=False)  # allocates nothing: no Numba runtime
def _corner_normals(corner_angle, face_unit, order, starts, cos_crease, out):
    n_keys = starts.shape[0] - 1
    for k in range(n_keys):
        lo = starts[k]
        hi = starts[k + 1]
        for a in range(lo, hi):
            ca = order[a]
            fa = ca // 3
            sx = 0.0
            sy = 0.0
            sz = 0.0
            for b in range(lo, hi):
                cb = order[b]
                fb = cb // 3
                c = (face_unit[fa, 0] * face_unit[fb, 0] + face_unit[fa, 1] * face_unit[fb, 1]
                     + face_unit[fa, 2] * face_unit[fb, 2])
                if fb == fa or c >= cos_crease:
                    w = corner_angle[fb, cb % 3]
                    sx += w * face_unit[fb, 0]
                    sy += w * face_unit[fb, 1]
                    sz += w * face_unit[fb, 2]
            length = np.sqrt(sx * sx + sy * sy + sz * sz)
            if length > 0.0:
                out[fa, ca % 3, 0] = sx / length
                out[fa, ca % 3, 1] = sy / length
                out[fa, ca % 3, 2] = sz / length
            else:
                out[fa, ca % 3, 0] = face_unit[fa, 0]
                out[fa, ca % 3, 1] = face_unit[fa, 1]
                out[fa, ca % 3, 2] = face_unit[fa, 2]


def smooth_corner_normals(vertices: np.ndarray, faces: np.ndarray,
                          crease_angle: float) -> np.ndarray:
    """(T, 3, 3) float32 unit normals at the three corners of every triangle."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    raw = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    length = np.linalg.norm(raw, axis=1)
    unit = raw / np.where(length > 0, length, 1.0)[:, None]
    p = v[f]  # (T, 3 corners, 3)
    angle = np.empty((len(f), 3))
    for k in range(3):
        a = p[:, (k + 1) % 3] - p[:, k]
        b = p[:, (k + 2) % 3] - p[:, k]
        angle[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1),
                                 np.einsum("ij,ij->i", a, b))
    _, weld = np.unique(v, axis=0, return_inverse=True)
    weld = weld.reshape(-1)
    corner_key = weld[f.reshape(-1)]
    order = np.argsort(corner_key, kind="stable").astype(np.int64)
    counts = np.bincount(corner_key, minlength=int(weld.max(initial=-1)) + 1)
    starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    out = np.zeros((len(f), 3, 3), np.float32)
    cos_crease = float(np.cos(np.radians(min(max(crease_angle, 0.0), 180.0))))
    # a hair of slack so faces exactly at the crease angle (a cube's 90 deg at 90) join
    corner_normals = for_size(_corner_normals, len(f), PYTHON_LIMIT)
    corner_normals(angle, unit, order, starts, cos_crease - 1e-9, out)
    return out
