"""Compiled variants of a kernel that differ only in the kernels they call.

Numba links every kernel a function calls into its compiled code, so a kernel that may call
either of two others (the serial or the parallel law pass) would compile both wherever it is
compiled, and ``parallel=True`` code takes long to compile. :func:`rebind` makes a copy of the
Python function whose global names point elsewhere; compiled under its own name it is cached
apart (Numba names cache files by the function's qualified name).
"""

from __future__ import annotations

import types
from typing import Any, Callable


def rebind(fn: Callable[..., Any], name: str, **globals_: Any) -> types.FunctionType:
    """A copy of the plain Python function ``fn`` (a dispatcher's ``py_func``) named ``name``, in
    which the global names given as keywords refer to the given objects (every other global as in
    ``fn``'s module at the time of the call)."""
    missing = [k for k in globals_ if k not in fn.__globals__]
    if missing:
        raise NameError(f"rebind: {fn.__qualname__} has no globals {missing}")
    scope = dict(fn.__globals__)
    scope.update(globals_)
    out = types.FunctionType(fn.__code__, scope, name, fn.__defaults__, fn.__closure__)
    out.__qualname__ = name
    out.__doc__ = fn.__doc__
    out.__module__ = fn.__module__
    out.__annotations__ = dict(fn.__annotations__)
    return out
