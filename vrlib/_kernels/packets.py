"""Ray packets: the trilinear samples of eight rays at once, in vector form.

numba has no vector types, and LLVM, as numba drives it, vectorises neither a loop over lanes
that reads a table at eight indices nor the arithmetic around it (docs/kernel.md, "Packets").
:func:`trilinear_packet` writes the whole sample out in LLVM's vectors instead: the eight
positions become one vector per axis; floor, fractions and base indices are vector
operations; each of the cell's eight corners is one ``llvm.masked.gather`` (an AVX2 or
AVX-512 gather where the CPU has one, scalar loads elsewhere); the seven lerps run on
vectors. The roofline measures it beside the scalar loop (:mod:`vrlib.roofline`): it is the
packet-sampling ceiling, what the sampling alone of a packet kernel could reach here.

The arithmetic is the scalar loop's, lane by lane (``a + t (b - a)`` along x, then y, then
z), in float64: float32 samples are widened before the lerps, where the scalar loop takes
the corners' differences in float32 (the two differ by float32 rounding, about 1e-7).
"""

from __future__ import annotations

import numba
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

#: Rays in a packet: one AVX-512 vector of float64.
LANES = 8

_I32 = ir.IntType(32)


def _vector(builder, values, vector_type):
    """The tuple ``values`` (``LANES`` scalars) as one vector."""
    vector = ir.Constant(vector_type, None)
    for lane in range(LANES):
        vector = builder.insert_element(vector, builder.extract_value(values, lane), _I32(lane))
    return vector


def _splat(builder, value, vector_type):
    """``value`` in every lane."""
    vector = builder.insert_element(ir.Constant(vector_type, None), value, _I32(0))
    return builder.shuffle_vector(vector, ir.Constant(vector_type, None),
                                  ir.Constant(ir.VectorType(_I32, LANES), [0] * LANES))


@intrinsic
def _trilinear_packet(typingctx, flat, nx, nxy, ux, uy, uz):
    packet = types.UniTuple(types.float64, LANES)
    if not (isinstance(flat, types.Array) and flat.ndim == 1
            and flat.dtype in (types.float32, types.float64)
            and all(isinstance(u, types.UniTuple) and u.count == LANES
                    and u.dtype == types.float64 for u in (ux, uy, uz))):
        return None

    def codegen(context, builder, signature, args):
        array_type, nx_type, nxy_type = signature.args[:3]
        array = context.make_array(array_type)(context, builder, args[0])
        stored = context.get_data_type(array_type.dtype)
        f64, i64 = ir.DoubleType(), ir.IntType(64)
        floats, ints = ir.VectorType(f64, LANES), ir.VectorType(i64, LANES)
        # Positions, their cells (floor: positions are >= 0) and fractions.
        u = [_vector(builder, value, floats) for value in args[3:6]]
        cell = [builder.fptosi(value, ints) for value in u]
        t = [builder.fsub(u[axis], builder.sitofp(cell[axis], floats)) for axis in range(3)]
        row = _splat(builder, context.cast(builder, args[1], nx_type, types.intp), ints)
        plane = _splat(builder, context.cast(builder, args[2], nxy_type, types.intp), ints)
        base = builder.add(builder.add(builder.mul(cell[2], plane), builder.mul(cell[1], row)),
                           cell[0])
        # One gather per corner, from the addresses base + offset.
        size = context.get_abi_sizeof(stored)
        start = _splat(builder, builder.ptrtoint(array.data, i64), ints)
        loaded = ir.VectorType(stored, LANES)
        everyone = ir.Constant(ir.VectorType(ir.IntType(1), LANES), [1] * LANES)
        pointers = ir.VectorType(array.data.type, LANES)
        gather = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(loaded, [pointers, _I32, everyone.type, loaded]),
            f"llvm.masked.gather.v{LANES}{'f64' if stored == f64 else 'f32'}.v{LANES}p0")

        def corner(offset):
            index = builder.add(base, offset)
            address = builder.add(start, builder.mul(index, ir.Constant(ints, [size] * LANES)))
            value = builder.call(gather, [builder.inttoptr(address, pointers), _I32(size),
                                          everyone, ir.Constant(loaded, None)])
            return value if stored == f64 else builder.fpext(value, floats)

        one = ir.Constant(ints, [1] * LANES)
        both = builder.add(plane, row)
        d000, d001 = corner(ir.Constant(ints, [0] * LANES)), corner(one)
        d010, d011 = corner(row), corner(builder.add(row, one))
        d100, d101 = corner(plane), corner(builder.add(plane, one))
        d110, d111 = corner(both), corner(builder.add(both, one))

        def lerp(a, b, w):
            return builder.fadd(a, builder.fmul(w, builder.fsub(b, a)))

        # Along x, then y, then z (eq 1.1 with the tent filter).
        c0 = lerp(lerp(d000, d001, t[0]), lerp(d010, d011, t[0]), t[1])
        c1 = lerp(lerp(d100, d101, t[0]), lerp(d110, d111, t[0]), t[1])
        value = lerp(c0, c1, t[2])
        out = cgutils.get_null_value(context.get_value_type(signature.return_type))
        for lane in range(LANES):
            out = builder.insert_value(out, builder.extract_element(value, _I32(lane)), lane)
        return out

    return packet(flat, nx, nxy, ux, uy, uz), codegen


def _trilinear_lanes(flat, nx, nxy, ux, uy, uz):
    """:func:`trilinear_packet` one lane at a time (without the JIT)."""
    out = []
    for x, y, z in zip(ux, uy, uz, strict=True):
        ix, iy, iz = int(x), int(y), int(z)
        base = iz * nxy + iy * nx + ix
        d = [float(flat[base + offset]) for offset in
             (0, 1, nx, nx + 1, nxy, nxy + 1, nxy + nx, nxy + nx + 1)]
        tx, ty, tz = x - ix, y - iy, z - iz
        c = [d[i] + tx * (d[i + 1] - d[i]) for i in (0, 2, 4, 6)]
        c0, c1 = c[0] + ty * (c[1] - c[0]), c[2] + ty * (c[3] - c[2])
        out.append(c0 + tz * (c1 - c0))
    return tuple(out)


trilinear_packet = _trilinear_lanes if numba.config.DISABLE_JIT else _trilinear_packet
"""``trilinear_packet(flat, nx, nxy, ux, uy, uz)``: the trilinear samples, a tuple of
``LANES`` float64, of ``flat`` (a raveled ``[z, y, x]`` volume, float32 or float64, rows of
``nx`` samples, planes of ``nxy``) at the ``LANES`` index positions ``(ux[l], uy[l], uz[l])``
(tuples of float64), each in a cell whose eight corners lie inside the volume (no bounds
check, no clamp)."""
