"""Where a scene's objects are: world-space points spanning each object (its box corners, or a
mesh's vertices), for framing a camera and for the editor's selection boxes. Planes are
unbounded and have none."""

from __future__ import annotations

import numpy as np

from ..scene import Scene


def _corners(lo, hi) -> np.ndarray:
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                     for z in (lo[2], hi[2])])


def _ball(centre, radius: float) -> np.ndarray:
    c = np.asarray(centre, np.float64)
    return _corners(c - radius, c + radius)


def local_points(obj, scene: Scene | None = None) -> np.ndarray | None:
    """Points whose hull holds the object before its transform (None: unbounded, or a model
    file that cannot be read). A mesh file is read through the mesh cache."""
    t = obj.type
    if t == "sphere":
        return _ball(obj.center, obj.radius)
    if t == "box":
        if obj.min is not None:
            return _corners(obj.min, obj.max)
        c, e = np.asarray(obj.corner, np.float64), np.asarray(obj.edges, np.float64)
        return np.array([c + i * e[0] + j * e[1] + k * e[2]
                         for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    if t == "rectangle":
        c, a, b = (np.asarray(v, np.float64) for v in (obj.corner, obj.edge1, obj.edge2))
        return np.array([c, c + a, c + b, c + a + b])
    if t == "triangle":
        return np.asarray(obj.vertices, np.float64)
    if t == "disk":
        return _ball(obj.center, obj.radius)
    if t in ("cylinder", "cone"):
        r = obj.radius if t == "cylinder" else max(obj.radius, obj.top_radius or 0.0)
        return np.concatenate([_ball(obj.base, r), _ball(obj.top, r)])
    if t == "torus":  # about the y axis through the origin
        a = obj.major_radius + obj.minor_radius
        return _corners((-a, -obj.minor_radius, -a), (a, obj.minor_radius, a))
    if t == "csg":  # in the CSG object's space, from its parts
        children = obj.objects[:1] if obj.operation == "difference" else obj.objects
        parts = [p for o in children if (p := world_points(o, scene)) is not None]
        if not parts:
            return None
        if obj.operation == "intersection" and len(parts) == len(children):
            lo = np.max([p.min(axis=0) for p in parts], axis=0)
            hi = np.maximum(np.min([p.max(axis=0) for p in parts], axis=0), lo)
            return _corners(lo, hi)  # within every part's box
        return np.concatenate(parts)  # a difference within its first part; a union, all
    if t == "mesh":
        try:
            if obj.file is not None:
                from ..assets import load_mesh

                path = scene.resolve_path(obj.file) if scene is not None else obj.file
                v = load_mesh(path).vertices
            else:
                v = np.asarray(obj.vertices, np.float64)
        except Exception:  # noqa: BLE001 - an unreadable model has no bounds here
            return None
        v = v[np.all(np.isfinite(v), axis=1)]
        return v if len(v) else None
    return None


def world_points(obj, scene: Scene | None = None) -> np.ndarray | None:
    """:func:`local_points` after the object's transform."""
    pts = local_points(obj, scene)
    if pts is None:
        return None
    if obj.transform is not None:
        m = obj.transform.matrix()
        pts = pts @ m[:3, :3].T + m[:3, 3]
    return pts


def item_bounds(obj, scene: Scene | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """World-space box (lo, hi) around ``obj`` (its files found from ``scene``'s folder);
    None for an unbounded plane or an unreadable model."""
    pts = world_points(obj, scene)
    if pts is None:
        return None
    return pts.min(axis=0), pts.max(axis=0)
