"""scene/interpolate.py on the cases the films do not reach: unknown modes, stepped and
spline rotations (about one axis a rotation's spline is the number's spline), trees of
dicts with rotations and text, the leaves a tree interpolates, and spline turning points."""

from __future__ import annotations

import pytest

from whitted.scene.interpolate import (
    interpolate_rotation,
    interpolate_scalar,
    interpolate_tree,
    scalar_leaves,
    spline_extremes,
)


def test_unknown_modes():
    with pytest.raises(ValueError, match="^unknown interpolation 'cubic'$"):
        interpolate_scalar([0, 1], [0, 1], 0.5, "cubic")
    with pytest.raises(ValueError, match="^unknown interpolation 'cubic'$"):
        interpolate_rotation([0, 1], [[0, 0, 0], [0, 90, 0]], 0.5, "cubic")


def test_stepped_and_linear_rotations():
    keys = [[0, 0, 0], [0, 90, 0]]
    assert interpolate_rotation([0, 10], keys, 5, "step") == (0.0, 0.0, 0.0)
    assert interpolate_rotation([0, 10], keys, 10, "step") == (0.0, 90.0, 0.0)
    assert interpolate_rotation([0, 10], keys, 5, "linear") == pytest.approx((0, 45, 0))
    assert interpolate_rotation([0, 10], keys, 5, "smooth") == pytest.approx((0, 45, 0))


@pytest.mark.parametrize("t", [2, 5, 8, 12, 15])
def test_a_spline_rotation_about_one_axis_is_the_numbers_spline(t):
    # two equal keys first (the rotation between them is none: log of the identity)
    angles = interpolate_rotation([0, 10, 20], [[0, 0, 0], [0, 0, 0], [0, 90, 0]], t,
                                  "spline")
    y = interpolate_scalar([0, 10, 20], [0, 0, 90], t, "spline")
    assert angles == pytest.approx((0.0, y, 0.0), abs=1e-9)
    assert interpolate_scalar([0, 10, 20], [0, 0, 90], 5, "spline") == -5.625  # overshoot


def test_trees_of_numbers_rotations_and_text():
    keys = [{"a": 0, "b": "x", "rotate": [0, 0, 0], "c": [1.0, 2.0]},
            {"a": 10, "b": "y", "rotate": [0, 90, 0], "c": [3.0, 6.0]}]
    out = interpolate_tree([0, 10], keys, 5, "linear")
    assert out["a"] == 5 and isinstance(out["a"], int)  # whole keys stay whole
    assert out["b"] == "x"  # text steps
    assert out["rotate"] == pytest.approx([0, 45, 0]) and out["c"] == [2.0, 4.0]
    # dicts of other keys: the whole value steps
    assert interpolate_tree([0, 10], [{"a": 0}, {"c": 10}], 5, "linear") == {"a": 0}
    assert interpolate_tree([0, 10], [{"a": 0}, {"c": 10}], 10, "linear") == {"c": 10}


def test_the_leaves_a_tree_interpolates():
    assert scalar_leaves([1]) == []  # one key: nothing moves
    assert scalar_leaves([[1, 2], [3, 4]]) == [[1.0, 3.0], [2.0, 4.0]]
    assert scalar_leaves([{"rotate": [0, 0, 0], "x": 1}, {"rotate": [0, 90, 0], "x": 2}]) == \
        [[1.0, 2.0]]  # rotations are left out
    assert scalar_leaves(["a", "b"]) == [] and scalar_leaves([{"a": 1}, {"b": 2}]) == []


def test_spline_turning_points():
    # 0, 0, 1: the first segment dips to its minimum (-2/27) at s = 2/3 (a linear slope)
    (t,) = spline_extremes([0, 1, 2], [0, 0, 1])
    assert t == pytest.approx(2 / 3)
    assert interpolate_scalar([0, 1, 2], [0, 0, 1], t, "spline") == pytest.approx(-2 / 27)
    assert spline_extremes([0, 1, 2], [0, 1, 2]) == []  # a straight line never turns
