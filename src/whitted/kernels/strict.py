"""IEEE twins of kernels: the same code compiled without fast-math, every kernel and overload
it calls twinned the same way, so that it computes the same bits however it was obtained.

Render kernels are compiled with fast-math (jit/decorators.py): LLVM may fuse a multiply and an
add into one FMA instruction, reassociate sums, replace a division by a multiplication with
a reciprocal. What it does depends on the CPU target (``NUMBA_CPU_NAME=generic`` has no FMA)
and on what it sees of the code around (a callee inlined or not, which depends on the order
kernels were compiled in, in this process or in the one whose cache it loads). For the image
that is a last-bit difference. The photons of caustics amplify such differences: a photon
landing 1e-16 on the other side of a grid cell or a decision moves the fitted gather radius
and the whole caustic with it. So the photon tracer runs as a twin made here
(:func:`strict`): every floating-point operation rounded as IEEE 754 prescribes, in source
order, nothing fused or reordered, so the photons are the same bits on every CPU target, cold
compiled or loaded from the cache. (The C library's sin, cos and exp are the one thing
left: the same on one machine; docs/caustics.md.)

A twin is a copy of the kernel's Python function with its own globals, where each kernel it
calls is that kernel's twin and each function with an overload (jit/decorators.py ``overload``)
a copy whose overload runs with twinned globals (its lambdas call twins; a kernel's body it
returns, jit/decorators.py ``body``, is the twin's). The twins in those globals get
their Numba dispatchers as a module's kernels do, before Numba's first compile in the process
(jit/decorators.py ``kernels_in_globals``): loading the tracer from the cache makes one
dispatcher, not one per kernel it calls (each with its cache files looked up). A twin's name ends in
``__ieee`` (its cache files are its own) and its options are the kernel's with
``fastmath=False``.
"""

from __future__ import annotations

import types

from ..jit import decorators as jit

SUFFIX = "__ieee"

_twins: dict = {}  # the original Python function -> its twin (Kernel or function)


def strict(target):
    """The IEEE twin of kernel ``target`` (a Kernel, or its dispatcher): called like it."""
    if jit._jit_disabled():  # kernels are plain Python: nothing to compile either way
        return target
    jit.load_numba()
    kern = _kernel_of(target)
    if kern is None:
        raise TypeError(f"{target!r} is not a whitted kernel")
    with jit._lock:
        twin = _twin_kernel(kern)
    return twin if twin.entry else twin.dispatcher


def _kernel_of(value):
    if isinstance(value, jit.Kernel):
        return value
    py_func = getattr(value, "py_func", None)
    if py_func is None:
        return None
    return jit.kernels_by_function.get(py_func)


def _names(code) -> set[str]:
    """Global names ``code`` and the code nested in it (lambdas, closures) may read."""
    found = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            found |= _names(const)
    return found


def _copy(f, qualname: str):
    """A copy of function ``f`` with globals of its own (a copy of its module's)."""
    made = types.FunctionType(f.__code__, dict(f.__globals__), f.__name__, f.__defaults__,
                              f.__closure__)
    made.__qualname__ = qualname
    made.__module__ = f.__module__
    made.__doc__ = f.__doc__
    made.__kwdefaults__ = f.__kwdefaults__
    return made


def _twin_globals(f, copy) -> None:
    """Point the names ``copy`` (a copy of ``f``) reads at the twins of the kernels and
    overloaded functions they name."""
    g = copy.__globals__
    for name in _names(f.__code__):
        value = g.get(name)
        if value is None or value is f:
            continue
        if isinstance(value, jit.NumbaObject):  # not swapped in yet (jit/decorators.py)
            g[name] = value = value.resolve()
        kern = _kernel_of(value)
        if kern is not None:
            g[name] = _twin_kernel(kern)
        elif callable(value) and value in jit.overloads_by_function:
            g[name] = _twin_overloaded(value)
    # the twins' dispatchers are made only if Numba compiles (jit/decorators.py): a process
    # that loads the tracer from the cache never makes the 120-odd of its callees
    jit.kernels_in_globals(g)


def _twin_kernel(kern):
    f = kern.py_func
    twin = _twins.get(f)
    if twin is not None:
        return twin
    copy = _copy(f, f.__qualname__ + SUFFIX)
    options = dict(kern.options)
    options["fastmath"] = False
    twin = jit.Kernel(copy, options, kern.specialise_constants, kern.cache, kern.entry)
    _twins[f] = twin
    _twin_globals(f, copy)
    return twin


def _twin_overloaded(function):
    """A copy of ``function`` (a Python function kernels call, with an overload) whose
    overload is the original's with twinned globals: the lambdas it returns call twins, and
    the kernel's body it returns is the twin's."""
    twin = _twins.get(function)
    if twin is not None:
        return twin
    implementation, options = jit.overloads_by_function[function]
    twin = _copy(function, function.__qualname__ + SUFFIX)
    _twins[function] = twin
    twin_impl = _copy(implementation, implementation.__qualname__ + SUFFIX)
    _twin_globals(implementation, twin_impl)
    jit.register_overload(twin, twin_impl, options)
    return twin
