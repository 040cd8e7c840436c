"""A cache prefetch hint for compiled kernels: ``prefetch(array, (i, j, ...))`` asks the processor
to bring the cache line of ``array[i, j, ...]`` in ahead of its use (LLVM's ``llvm.prefetch``, a
read with high locality). It changes no value: the hint cannot fault, and a kernel computes the
same answer bit for bit with or without it.

The joint law of a large assembly is bound by memory latency as much as by arithmetic: a face
pair's data (its blocks' poses, its faces' frames, its points' model entries and slot state) lies
in a dozen arrays at addresses that jump from pair to pair, several MB in all for the 1000-brick
wall, more than the caches hold. :func:`rockdem.kernels.forces._law_pairs` asks for the lines of
the pair two ahead while it computes the current one (docs/performance.md).
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic


@intrinsic
def prefetch(typingctx: Any, array: Any, index: Any) -> Any:
    """(array, index tuple) -> None: prefetch the cache line of ``array[index]`` (no bounds check,
    none needed: a prefetch never faults)."""
    if not isinstance(array, types.Array) or not isinstance(index, types.BaseTuple) or len(index) != array.ndim:
        return None

    def codegen(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        aryty = sig.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        indices = cgutils.unpack_tuple(builder, args[1], len(sig.args[1]))
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, indices, wraparound=False)
        i8p = ir.IntType(8).as_pointer()
        i32 = ir.IntType(32)
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]), "llvm.prefetch.p0")
        # read (0), high temporal locality (3), data cache (1)
        builder.call(fn, [builder.bitcast(ptr, i8p), ir.Constant(i32, 0), ir.Constant(i32, 3), ir.Constant(i32, 1)])
        return context.get_dummy_value()

    return types.none(array, index), codegen
