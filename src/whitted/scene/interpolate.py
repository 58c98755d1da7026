"""Interpolation between keys: step, linear, smooth, spline; rotations by quaternions.

Every function here is plain arithmetic on numbers and small NumPy arrays.

* ``step``: the value of the last key at or before the frame.
* ``linear``: straight lines between keys.
* ``smooth``: cubic ease in and out between each pair of keys (Hermite with zero slope at every
  key: the value comes to rest at each key, like Blender's "ease" keys).
* ``spline``: a cubic through the keys with continuous slope (Catmull-Rom: the slope at a key
  is the difference of its two neighbours over their distance in frames; the end keys use
  their one neighbour). It can overshoot between keys.

Before the first key the value holds at the first key's value, after the last key at the
last one (constant extrapolation); in a cyclic animation the keys repeat every ``frames``
frames instead (:func:`wrap_keys`), so the value runs from the last key back to the first.

Rotations (``rotate`` fields: degrees about x, then y, then z) are turned into unit
quaternions, each key's quaternion on the same side as the previous one (so every segment
turns the shortest way, never the long way round), and interpolated as rotations: ``linear``
is slerp, ``smooth`` slerp with eased time, ``spline`` Shoemake's squad (a quaternion cubic
through the keys). The result is turned back into angles about x, y, z. A turn of 180 degrees
or more between two keys therefore needs a key in between: 0 -> 360 is no turn at all.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

INTERPOLATIONS = ("step", "linear", "smooth", "spline")

__all__ = [
    "INTERPOLATIONS", "euler_to_quaternion", "interpolate_rotation", "interpolate_scalar",
    "interpolate_tree", "quaternion_to_euler", "slerp", "wrap_keys",
]


def _segment(times: Sequence[float], t: float) -> tuple[int, float]:
    """Index i of the segment times[i]..times[i+1] holding t and the fraction through it."""
    i = bisect.bisect_right(times, t) - 1
    i = min(max(i, 0), len(times) - 2)
    h = times[i + 1] - times[i]
    return i, (t - times[i]) / h


def interpolate_scalar(times: Sequence[float], values: Sequence[float], t: float,
                       mode: str) -> float:
    """The value at frame ``t`` of keys ``(times[i], values[i])`` (times ascending)."""
    if mode not in INTERPOLATIONS:
        raise ValueError(f"unknown interpolation {mode!r}")
    if t <= times[0] or len(times) == 1:
        return float(values[0])
    if t >= times[-1]:
        return float(values[-1])
    if mode == "step":
        return float(values[bisect.bisect_right(times, t) - 1])
    i, s = _segment(times, t)
    p0, p1 = float(values[i]), float(values[i + 1])
    if mode == "linear":
        return p0 + (p1 - p0) * s
    if mode == "smooth":
        return p0 + (p1 - p0) * s * s * (3.0 - 2.0 * s)
    h = times[i + 1] - times[i]
    m0 = _slope(times, values, i)
    m1 = _slope(times, values, i + 1)
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * h * m0
            + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * h * m1)


def _slope(times: Sequence[float], values: Sequence[float], i: int) -> float:
    """Catmull-Rom slope at key i (per frame)."""
    lo, hi = max(i - 1, 0), min(i + 1, len(times) - 1)
    return (float(values[hi]) - float(values[lo])) / (times[hi] - times[lo])


# ------------------------------------------------------------------------------ rotations


def _axis_quaternion(axis: int, degrees: float) -> np.ndarray:
    half = math.radians(degrees) / 2
    q = np.zeros(4)
    q[0] = math.cos(half)
    q[1 + axis] = math.sin(half)
    return q


def _qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ])


def euler_to_quaternion(angles: Sequence[float]) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation about x, then y, then z (degrees): the
    matrix Rz·Ry·Rx that :class:`~whitted.Transform` and the camera's ``rotate`` use."""
    qx = _axis_quaternion(0, angles[0])
    qy = _axis_quaternion(1, angles[1])
    qz = _axis_quaternion(2, angles[2])
    return _qmul(qz, _qmul(qy, qx))


def quaternion_matrix(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def quaternion_to_euler(q: np.ndarray, near: Sequence[float] | None = None
                        ) -> tuple[float, float, float]:
    """Angles (degrees) about x, then y, then z whose rotation is ``q``: y in -90..90, or,
    given ``near``, of the two angle triples of every rotation (and their turns by 360
    degrees) the one closest to ``near`` (so keyed angles read back as written)."""
    a, b, c = _euler(q)
    if near is None:
        return a, b, c
    best: tuple[float, float, float] = (a, b, c)
    best_d = math.inf
    for cand in ((a, b, c), (a + 180.0, 180.0 - b, c + 180.0)):
        shifted = tuple(v + 360.0 * round((n - v) / 360.0) for v, n in zip(cand, near,
                                                                           strict=True))
        d = sum((v - n) ** 2 for v, n in zip(shifted, near, strict=True))
        if d < best_d - 1e-9:
            best, best_d = shifted, d  # type: ignore[assignment]
    return (_clean(best[0]), _clean(best[1]), _clean(best[2]))


def _euler(q: np.ndarray) -> tuple[float, float, float]:
    m = quaternion_matrix(q)
    sy = -m[2, 0]
    sy = max(-1.0, min(1.0, sy))
    b = math.asin(sy)
    if abs(m[2, 0]) < 1.0 - 1e-12:
        a = math.atan2(m[2, 1], m[2, 2])
        c = math.atan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: y = +-90 degrees; put the whole turn about x
        c = 0.0
        a = math.atan2(-m[1, 2], m[1, 1])
    return (_clean(math.degrees(a)), _clean(math.degrees(b)), _clean(math.degrees(c)))


def _clean(deg: float) -> float:
    r = round(deg, 9)
    return 0.0 if r == 0 else r


def slerp(q0: np.ndarray, q1: np.ndarray, s: float) -> np.ndarray:
    """Spherical linear interpolation of unit quaternions (no hemisphere flip here: the
    caller chooses the sign of ``q1``)."""
    d = float(np.clip(np.dot(q0, q1), -1.0, 1.0))
    if d > 1.0 - 1e-12:
        q = q0 + (q1 - q0) * s
        return q / np.linalg.norm(q)
    theta = math.acos(d)
    sin = math.sin(theta)
    return (math.sin((1 - s) * theta) * q0 + math.sin(s * theta) * q1) / sin


def _qlog(q: np.ndarray) -> np.ndarray:
    v = q[1:]
    n = float(np.linalg.norm(v))
    if n < 1e-15:
        return np.zeros(4)
    angle = math.atan2(n, q[0])
    return np.concatenate([[0.0], v / n * angle])


def _qexp(q: np.ndarray) -> np.ndarray:
    v = q[1:]
    n = float(np.linalg.norm(v))
    if n < 1e-15:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[math.cos(n)], v / n * math.sin(n)])


def _qinv(q: np.ndarray) -> np.ndarray:
    return np.array([q[0], -q[1], -q[2], -q[3]])


def _squad_control(prev: np.ndarray, q: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    inv = _qinv(q)
    return _qmul(q, _qexp(-(_qlog(_qmul(inv, nxt)) + _qlog(_qmul(inv, prev))) / 4))


def same_side(quaternions: list[np.ndarray]) -> list[np.ndarray]:
    """Each quaternion negated where needed so that it lies in the same hemisphere as the one
    before it: q and -q are the same rotation, and this makes each segment the short way."""
    out = [quaternions[0]]
    for q in quaternions[1:]:
        out.append(-q if np.dot(out[-1], q) < 0 else q)
    return out


def interpolate_rotation(times: Sequence[float], angles: Sequence[Sequence[float]], t: float,
                         mode: str) -> tuple[float, float, float]:
    """The rotation at frame ``t`` of keyed rotations (degrees about x, y, z), as angles."""
    if mode not in INTERPOLATIONS:
        raise ValueError(f"unknown interpolation {mode!r}")
    if t <= times[0] or len(times) == 1:
        return tuple(float(a) for a in angles[0])  # type: ignore[return-value]
    if t >= times[-1]:
        return tuple(float(a) for a in angles[-1])  # type: ignore[return-value]
    if mode == "step":
        k = bisect.bisect_right(times, t) - 1
        return tuple(float(a) for a in angles[k])  # type: ignore[return-value]
    qs = same_side([euler_to_quaternion(a) for a in angles])
    i, s = _segment(times, t)
    if mode == "linear":
        q = slerp(qs[i], qs[i + 1], s)
    elif mode == "smooth":
        q = slerp(qs[i], qs[i + 1], s * s * (3.0 - 2.0 * s))
    else:
        # past an end key, its neighbour mirrored (q0·q1⁻¹·q0): the end slope is one-sided,
        # as for numbers
        before = qs[i - 1] if i > 0 else _qmul(qs[0], _qmul(_qinv(qs[1]), qs[0]))
        last = len(qs) - 1
        after = (qs[i + 2] if i + 2 <= last
                 else _qmul(qs[last], _qmul(_qinv(qs[last - 1]), qs[last])))
        a = _squad_control(before, qs[i], qs[i + 1])
        b = _squad_control(qs[i], qs[i + 1], after)
        q = slerp(slerp(qs[i], qs[i + 1], s), slerp(a, b, s), 2 * s * (1 - s))
    near = [float(x0) + (float(x1) - float(x0)) * s
            for x0, x1 in zip(angles[i], angles[i + 1], strict=True)]
    return quaternion_to_euler(q, near)


# ------------------------------------------------------------------------------ trees

ROTATION_FIELDS = frozenset({"rotate"})


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def interpolate_tree(times: Sequence[float], values: Sequence[Any], t: float, mode: str,
                     name: str | None = None) -> Any:
    """Interpolate keyed values that are numbers, lists and dicts (a model's fields) leaf by
    leaf. Lists of three numbers under a ``rotate`` key are rotations. Leaves that are not
    numbers, or whose shape differs between keys, step. A number whose keys are all whole
    numbers stays whole (rounded)."""
    if mode == "step" or len(values) == 1:
        return values[_step_index(times, t)]
    if all(_is_number(v) for v in values):
        x = interpolate_scalar(times, [float(v) for v in values], t, mode)
        return round(x) if all(isinstance(v, int) for v in values) else x
    if all(isinstance(v, list | tuple) for v in values) and len({len(v) for v in values}) == 1:
        n = len(values[0])
        if (name in ROTATION_FIELDS and n == 3
                and all(_is_number(c) for v in values for c in v)):
            return list(interpolate_rotation(times, values, t, mode))
        return [interpolate_tree(times, [v[k] for v in values], t, mode) for k in range(n)]
    if all(isinstance(v, dict) for v in values) and len({tuple(v) for v in values}) == 1:
        return {k: interpolate_tree(times, [v[k] for v in values], t, mode, k)
                for k in values[0]}
    return values[_step_index(times, t)]


def wrap_keys(times: Sequence[float], values: Sequence[Any], period: float
              ) -> tuple[list[float], list[Any]]:
    """Keys of a cyclic animation (frame ``period`` is frame 0 again) with the last two keys
    repeated one period earlier and the first two one period later, so that interpolating
    the result anywhere in 0 .. period runs from the last key back round to the first (and a
    spline's slope at the ends comes from the other end's keys)."""
    n = min(2, len(times))
    before_t = [t - period for t in times[-n:]]
    after_t = [t + period for t in times[:n]]
    return ([*before_t, *times, *after_t],
            [*values[-n:], *values, *values[:n]])


def _step_index(times: Sequence[float], t: float) -> int:
    return max(0, bisect.bisect_right(times, t) - 1)
