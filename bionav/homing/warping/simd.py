"""Explicit SIMD vectors for numba kernels: LLVM vector types and a few operations on them.

numba vectorises plain loops with LLVM's loop vectoriser, which keeps every
value that lives across iterations in memory. The warping kernels need values
that live in registers across a whole loop nest (the running minima of a
snapshot column over its windows, the 16-bit distance sums of a column block
over all rows). This module gives numba two fixed-width vector types and the
handful of operations the kernels use, each one LLVM instruction on vector
values (``<32 x i8>``, ``<32 x i16>``), so the code states the vector width and
LLVM only chooses the registers: ``ymm`` pairs on AVX2, one ``zmm`` or two
``ymm`` on AVX-512, ``xmm`` groups on SSE or NEON; no masked loads or stores
anywhere (checked by ``tests/project/test_kernel_codegen.py``).

Conventions
-----------
* ``U8x32``: 32 unsigned bytes; ``I16x32``: 32 16-bit integers (wrapping
  arithmetic, read as unsigned where a kernel says so).
* Loads and stores take a C-contiguous array and an element offset (``intp``);
  they are unaligned and **unchecked**: the caller keeps ``offset + 32``
  within the array (the kernels pad their buffers for it).
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.extending import intrinsic, models, register_model

#: lanes of both vector types
LANES = 32

_I8 = ir.IntType(8)
_I16 = ir.IntType(16)
_V8 = ir.VectorType(_I8, LANES)
_V16 = ir.VectorType(_I16, LANES)


class U8x32Type(types.Type):
    """numba type of 32 unsigned bytes in one vector value."""

    def __init__(self) -> None:
        super().__init__(name="U8x32")


class I16x32Type(types.Type):
    """numba type of 32 16-bit integers in one vector value."""

    def __init__(self) -> None:
        super().__init__(name="I16x32")


U8x32 = U8x32Type()
I16x32 = I16x32Type()


@register_model(U8x32Type)
class _U8x32Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type) -> None:
        super().__init__(dmm, fe_type, _V8)


@register_model(I16x32Type)
class _I16x32Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type) -> None:
        super().__init__(dmm, fe_type, _V16)


def _pointer(context, builder, arrty, arr, offset, vtype):
    data = context.make_array(arrty)(context, builder, arr).data
    return builder.bitcast(builder.gep(data, [offset]), vtype.as_pointer())


def _loader(vtype, ntype, dtypes):
    def typer(typingctx, arr, offset):
        if not isinstance(arr, types.Array) or arr.dtype not in dtypes or arr.layout != "C":
            raise TypeError(f"expected a C-contiguous array of {dtypes}, got {arr}")

        def codegen(context, builder, sig, args):
            value = builder.load(_pointer(context, builder, sig.args[0], args[0], args[1], vtype))
            value.align = 1
            return value

        return ntype(arr, types.intp), codegen

    return typer


def _storer(vtype, ntype, dtypes):
    def typer(typingctx, arr, offset, value):
        if not isinstance(arr, types.Array) or arr.dtype not in dtypes or arr.layout != "C":
            raise TypeError(f"expected a C-contiguous array of {dtypes}, got {arr}")

        def codegen(context, builder, sig, args):
            store = builder.store(args[2], _pointer(context, builder, sig.args[0], args[0], args[1], vtype))
            store.align = 1
            return context.get_dummy_value()

        return types.void(arr, types.intp, ntype), codegen

    return typer


load_u8 = intrinsic(_loader(_V8, U8x32, (types.uint8,)))
load_u8.__doc__ = "``U8x32`` from ``arr[offset:offset + 32]`` (uint8 array)."
store_u8 = intrinsic(_storer(_V8, U8x32, (types.uint8,)))
store_u8.__doc__ = "``arr[offset:offset + 32] = value`` (uint8 array)."
load_i16 = intrinsic(_loader(_V16, I16x32, (types.int16, types.uint16)))
load_i16.__doc__ = "``I16x32`` from ``arr[offset:offset + 32]`` (int16 or uint16 array)."
store_i16 = intrinsic(_storer(_V16, I16x32, (types.int16, types.uint16)))
store_i16.__doc__ = "``arr[offset:offset + 32] = value`` (int16 or uint16 array)."


@intrinsic
def splat_u8(typingctx, x):
    """``U8x32`` with every lane ``x`` (a uint8)."""
    if x != types.uint8:
        raise TypeError(f"splat_u8 needs a uint8, got {x}")

    def codegen(context, builder, sig, args):
        v = builder.insert_element(ir.Constant(_V8, ir.Undefined), args[0], ir.Constant(ir.IntType(32), 0))
        return builder.shuffle_vector(v, v, ir.Constant(ir.VectorType(ir.IntType(32), LANES), [0] * LANES))

    return U8x32(types.uint8), codegen


@intrinsic
def zero_i16(typingctx):
    """``I16x32`` of zeros."""
    def codegen(context, builder, sig, args):
        return ir.Constant(_V16, None)

    return I16x32(), codegen


@intrinsic
def min_u8(typingctx, a, b):
    """Lane-wise unsigned minimum of two ``U8x32`` (``vpminub``)."""
    def codegen(context, builder, sig, args):
        return builder.select(builder.icmp_unsigned("<", args[0], args[1]), args[0], args[1])

    return U8x32(U8x32, U8x32), codegen


@intrinsic
def add_widened_u8(typingctx, acc, v):
    """``acc + v`` lane-wise, ``v`` (``U8x32``) zero-extended to 16 bits (``vpmovzxbw`` + ``vpaddw``)."""
    def codegen(context, builder, sig, args):
        return builder.add(args[0], builder.zext(args[1], _V16))

    return I16x32(I16x32, U8x32), codegen


@intrinsic
def add_max_i16(typingctx, acc, a, b):
    """``acc + max(a, b)`` lane-wise on ``I16x32``, signed maximum (``vpmaxsw`` + ``vpaddw``, wrapping)."""
    def codegen(context, builder, sig, args):
        return builder.add(args[0], builder.select(builder.icmp_signed(">", args[1], args[2]), args[1], args[2]))

    return I16x32(I16x32, I16x32, I16x32), codegen


@intrinsic
def add_i16(typingctx, a, b):
    """``a + b`` lane-wise on ``I16x32`` (``vpaddw``, wrapping)."""
    def codegen(context, builder, sig, args):
        return builder.add(args[0], args[1])

    return I16x32(I16x32, I16x32), codegen


@intrinsic
def sub_i16(typingctx, a, b):
    """``a - b`` lane-wise on ``I16x32`` (``vpsubw``, wrapping)."""
    def codegen(context, builder, sig, args):
        return builder.sub(args[0], args[1])

    return I16x32(I16x32, I16x32), codegen


@intrinsic
def add_absdiff_i16(typingctx, acc, a, b):
    """``acc + |a - b|`` lane-wise on ``I16x32`` (``vpsubw`` + ``vpabsw`` + ``vpaddw``, wrapping)."""
    def codegen(context, builder, sig, args):
        d = builder.sub(args[1], args[2])
        neg = builder.sub(ir.Constant(_V16, None), d)
        absd = builder.select(builder.icmp_signed("<", d, ir.Constant(_V16, None)), neg, d)
        return builder.add(args[0], absd)

    return I16x32(I16x32, I16x32, I16x32), codegen
