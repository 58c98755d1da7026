"""``geometry_ref_if_instances`` (kernels/geometry_ref.py): the scene's tuple of arrays itself
in kernels for scenes without mesh instances, tori or CSG, a one-pointer reference to it in
the others (tuned kernels only), typed and lowered there without a function of its own to
compile."""

from __future__ import annotations

import numba
import pytest
from numba.core import event

from whitted.jit import kernel, load_numba
from whitted.jit.dispatcher import tuned
from whitted.kernels.geometry_ref import GeometryRef, geometry_ref_if_instances
from whitted.render.warm_up import stand_in_scene

load_numba()


@pytest.mark.parametrize("general", [False, True])
def test_the_tuple_or_a_reference_and_no_compile_of_its_own(general):
    geo = stand_in_scene(general).geometry

    @kernel(entry=True, cache=False)  # compiled here, whatever the cache holds
    def read_through(geo):
        g = geometry_ref_if_instances(geo)
        return g.prim_info.shape[0] + g.inst_box.shape[0]

    with event.install_recorder("numba:compile") as compiles:
        count = read_through(geo)
    assert count == geo.prim_info.shape[0] + geo.inst_box.shape[0]
    compiled = {ev.data["dispatcher"].py_func.__qualname__ for _, ev in compiles.buffer}
    if tuned():  # the kernel (and its twin) alone: no overload's implementation
        assert compiled and all(".read_through" in name for name in compiled), compiled
    (result,) = read_through.dispatcher.overloads.values()
    returned = result.fndesc.typemap["g"]
    if general and tuned():  # one pointer to the tuple in this kernel's frame
        assert isinstance(returned, GeometryRef)
        assert returned.geometry == numba.typeof(geo)
    else:  # the tuple itself
        assert returned == numba.typeof(geo)


def test_python_runs_it_as_the_identity():
    geo = stand_in_scene(True).geometry
    assert geometry_ref_if_instances(geo) is geo


@pytest.mark.skipif(not tuned(), reason="stock Numba passes the tuple through an overload")
def test_a_kernel_with_numba_s_runtime_is_refused():
    """A function compiled with Numba's runtime (reference counts) would read the borrowed
    tuple as an owned one: compiling it fails, with the reason, instead."""
    geo = stand_in_scene(False).geometry

    @numba.njit  # Numba's runtime on: not a whitted kernel
    def counted(geo):
        g = geometry_ref_if_instances(geo)
        return g.prim_info.shape[0]

    with pytest.raises(Exception, match="a kernel with Numba's runtime"):
        counted(geo)
