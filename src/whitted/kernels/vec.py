"""Small 3-vector helpers on tuples (no heap allocation inside kernels)."""

from __future__ import annotations

import math

from ..jit import kernel


@kernel
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@kernel
def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@kernel
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@kernel
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@kernel
def scale(a, s):
    return (a[0] * s, a[1] * s, a[2] * s)


@kernel
def mul(a, b):
    return (a[0] * b[0], a[1] * b[1], a[2] * b[2])


@kernel
def madd(a, b, s):
    """a + b*s"""
    return (a[0] + b[0] * s, a[1] + b[1] * s, a[2] + b[2] * s)


@kernel
def normalize(a):
    n = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    if n == 0.0:
        return a
    inv = 1.0 / n
    return (a[0] * inv, a[1] * inv, a[2] * inv)


@kernel
def length(a):
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@kernel
def vload(arr, i, k):
    """The 3-vector arr[i, k:k+3] as a tuple."""
    return (arr[i, k], arr[i, k + 1], arr[i, k + 2])


@kernel
def max3(a):
    return max(a[0], max(a[1], a[2]))
