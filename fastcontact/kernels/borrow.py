"""Borrowed views of kernel records: the same arrays without their reference counts (private).

numba keeps NumPy arrays alive by an atomic reference count on each array's meminfo. A
namedtuple of arrays (a table, the time primitive) passed to a helper compiled with
``inline="always"`` is copied into the helper's variables, and each copy increments and later
decrements the count of *every* array in the record — whether the helper reads it or not —
in branches that numba's reference-count pruning does not remove. Measured on the squeeze
primitive (16 fields, 8 arrays), one thread, 1e6 random cases: the 4-point stencil in x0 cost
86 ns per case through the record against 14 ns through its borrowed view; ``t_of_z`` 139 vs
72 ns, its inverse ``z_of_t`` 349 vs 183 ns (results bit-identical). On several threads the
counts are also contended cache lines.

:func:`borrowed` returns the record with each array replaced by a view whose meminfo is NULL:
numba's increment and decrement test for NULL and do nothing. The view does not own its memory,
so it must not outlive the record it came from: take it at the top of a kernel from a record
the kernel received as an argument, use it inside that kernel (and its inlined helpers and
``prange`` bodies), never return or store it.

A record does not stay borrowed across a parallel loop: numba's parfor lowering passes the
arrays a ``prange`` body uses to the loop's worker function with their reference counts. The
parallel kernels therefore hand blocks of cases to a plain function that borrows its records
at its top (e.g. :func:`fastcontact.squeeze._fastpath.fast_kernel`): measured on the Barus
squeeze-out, one thread, 2e5 cases, 551 ns per case with the records borrowed only before the
loop, 288 ns borrowed in the block function.
"""
from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["borrowed"]


def _borrow_value(context, builder, typ, value):
    """The LLVM value of ``typ`` with every array inside it borrowed (NULL meminfo/parent)."""
    if isinstance(typ, types.Array):
        src = context.make_array(typ)(context, builder, value=value)
        dst = context.make_array(typ)(context, builder)
        for name in ("nitems", "itemsize", "data", "shape", "strides"):
            setattr(dst, name, getattr(src, name))
        dst.meminfo = cgutils.get_null_value(dst.meminfo.type)
        dst.parent = cgutils.get_null_value(dst.parent.type)
        return dst._getvalue()
    if isinstance(typ, types.BaseTuple):
        vals = [_borrow_value(context, builder, t, builder.extract_value(value, i))
                for i, t in enumerate(typ.types)]
        return context.make_tuple(builder, typ, vals)
    # anything else is passed through; the new record holds a reference of its own
    context.nrt.incref(builder, typ, value)
    return value


@intrinsic
def borrowed(typingctx, rec):
    """``rec`` (an array, or a tuple/namedtuple holding arrays, nested) with its arrays
    borrowed: same type, same data, no reference counting. See the module docstring for the
    lifetime rule."""
    if not isinstance(rec, (types.Array, types.BaseTuple)):
        return None

    def codegen(context, builder, sig, args):
        return _borrow_value(context, builder, sig.args[0], args[0])

    return rec(rec), codegen
