"""Views and copies inside compiled kernels (numba) that cost little to compile.

``borrow`` is a view without reference counting (``interceptor_row``'s scratch blocks);
``copy_into`` copies a vector into part of another with a loop.  A kernel that assigns an array
to a slice (``out[a:b] = x``) or reshapes one makes numba compile its error messages, which
format shapes as text (≈ 4 s of a cold compile, once per process); these two do not.
"""

from __future__ import annotations

from numba import carray, njit, types
from numba.extending import intrinsic


@intrinsic
def _address(typingctx, a, start):
    """The address of a[start] (a 1-D array) as a typed pointer."""
    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        return builder.gep(data, [args[1]])
    return types.CPointer(a.dtype)(a, types.intp), codegen


@njit(cache=True, inline="always")
def borrow(a, start, shape):
    """a[start:start + size] (a 1-D array) as a C-ordered array of ``shape`` that does not count
    references: its views cost no atomic reference counting (about a third of an evaluation
    otherwise) and no reshape.  Valid while ``a`` is; only for views that do not outlive the call."""
    size = 1
    for d in shape:
        size *= d
    if start < 0 or start + size > len(a):
        raise IndexError("borrow: outside the array")
    return carray(_address(a, start), shape)


@njit(cache=True, inline="always")
def copy_into(out, start, x) -> None:
    """out[start:start + len(x)] ← x (1-D arrays), element by element."""
    for i in range(len(x)):
        out[start + i] = x[i]
