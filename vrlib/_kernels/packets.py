"""Packets: eight rays, or eight pixels, at once in vector form.

numba has no vector types, and LLVM, as numba drives it, vectorises neither a loop over lanes
that reads a table at eight indices nor the arithmetic around it (docs/kernel.md, "Packets").
The functions here write the work out in LLVM's vectors instead: the eight rays' positions
become one vector per axis; floor, fractions and base indices are vector operations; what
each lane reads lies in pairs side by side (a cell's two corners along x, a table's entry
and the next, a pixel's two neighbours along a row), so each lane loads a pair in one
vector and :func:`_transposed` turns the eight lanes' loads into one vector per corner or
entry (``llvm.masked.gather``, a gather per value, took 12 to 23% longer on the Zen 4
machine: docs/kernel.md); the lerps run on vectors.

* :func:`inside_runs` is the ray caster's inner loop (:func:`vrlib._kernels.raycast.raycast`):
  each lane's run of samples inside the volume, classified from the table and composited
  front to back, with early termination per lane, until every lane's run has ended. Lane by
  lane it does the scalar loop's arithmetic, in the same order (the corners' differences in
  the stored type, as numba's scalar code takes them), so images are the same bit for bit.
  It asks for the cells a few samples ahead (``llvm.prefetch``).
* :func:`warp_octet_grey_pairs`, :func:`warp_octet_grey` and :func:`warp_octet_colour` are
  eight pixels of shear-warp's affine warp (:func:`vrlib._kernels.shear.warp_octet`): a
  pixel's two neighbours along a row, every channel, lie side by side, so each lane loads
  them in one vector per row and the loads are transposed into one vector per corner and
  channel (gathers of each value took 30% longer); the bilinear weights, clipping and the
  transparent test as vector operations and selects (numba's own ``min`` and ``max`` are
  selects too), the eight pixels interleaved into one store. Bit for bit the scalar pixel's
  arithmetic.
* :func:`trilinear_packet` is one trilinear sample of eight rays: the roofline measures it
  beside the scalar loop (:mod:`vrlib.roofline`), the packet-sampling ceiling. It widens
  float32 samples before their differences (within float32 rounding of the scalar loop).
"""

from __future__ import annotations

import numba
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from vrlib._kernels._jit import jit

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
        # A cell's two neighbours along x side by side: one load of the pair per lane and row
        # of the cell, transposed (as the renderer's packets, :func:`inside_runs`).
        size = context.get_abi_sizeof(stored)
        pair = ir.VectorType(stored, 2).as_pointer()
        corners = []
        for offset in (ir.Constant(ints, [0] * LANES), row, plane, builder.add(plane, row)):
            index = builder.add(base, offset)
            corners += [value if stored == f64 else builder.fpext(value, floats)
                        for value in _transposed(builder, [builder.load(builder.bitcast(
                            builder.gep(array.data, [builder.extract_element(index, _I32(lane))]),
                            pair), align=size) for lane in range(LANES)])]
        d000, d001, d010, d011, d100, d101, d110, d111 = corners

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


# The lanes' state for :func:`inside_runs`: rows of a (RAY_ROWS, LANES) float64 array and of
# a (2, LANES) int64 array.
AX, AY, AZ, BX, BY, BZ, RED, GREEN, BLUE, ALPHA = range(10)
RAY_ROWS = 10
K, END = 0, 1
#: How many samples ahead a packet asks for its rays' cells.
PREFETCH_AHEAD = 4


def _row(builder, data, row, element):
    """Pointer to row ``row`` of a C-contiguous ``(rows, LANES)`` array, as one vector."""
    return builder.bitcast(builder.gep(data, [ir.IntType(64)(row * LANES)]),
                           ir.VectorType(element, LANES).as_pointer())


def _mask(indices):
    """A shuffle's mask: ``indices`` into its two vectors laid end to end."""
    return ir.Constant(ir.VectorType(_I32, len(indices)), indices)


def _transposed(builder, rows):
    """The ``LANES`` (8) vectors ``rows``, one per lane of 2, 4 or 8 elements each, as one
    vector per element of ``LANES`` lanes: a transpose in rounds of two-vector shuffles, each
    of which AVX-512 does in one instruction (given one long shuffle of the rows laid end to
    end, LLVM took more: on VolPack's example the warp 0.21 against 0.19 ms)."""
    first, second = [0, 1, 2, 3, 8, 9, 10, 11], [4, 5, 6, 7, 12, 13, 14, 15]
    if rows[0].type.count == 2:
        # Lanes side by side, four at a time, then the two elements picked apart.
        while len(rows) > 2:
            size = 2 * rows[0].type.count
            rows = [builder.shuffle_vector(a, b, _mask(list(range(size))))
                    for a, b in zip(rows[::2], rows[1::2], strict=True)]
        return [builder.shuffle_vector(rows[0], rows[1], _mask(list(range(e, 16, 2))))
                for e in (0, 1)]
    if rows[0].type.count == 4:
        # Lanes side by side in pairs; quads[2 h + e]: lanes 4h .. 4h + 3 of element e,
        # then of element e + 2; halves joined.
        pairs = [builder.shuffle_vector(a, b, _mask(list(range(8))))
                 for a, b in zip(rows[::2], rows[1::2], strict=True)]
        quads = [builder.shuffle_vector(pairs[2 * h], pairs[2 * h + 1], _mask(
            [e + 4 * lane for lane in range(4)] + [e + 2 + 4 * lane for lane in range(4)]))
            for h in (0, 1) for e in (0, 1)]
        return [builder.shuffle_vector(quads[e % 2], quads[2 + e % 2],
                                       _mask(first if e < 2 else second)) for e in range(4)]
    # Eight elements: pairs[2 m + o], lanes 2m and 2m + 1 of elements o, o + 2, o + 4, o + 6
    # interleaved; quads[4 h + 2 o + s], lanes 4h .. 4h + 3 of elements o + 2s, then
    # o + 2s + 4; halves joined.
    pairs = [builder.shuffle_vector(a, b, _mask([k + o + lane for k in (0, 2, 4, 6)
                                                 for lane in (0, 8)]))
             for a, b in zip(rows[::2], rows[1::2], strict=True) for o in (0, 1)]
    quads = [builder.shuffle_vector(pairs[4 * h + o], pairs[4 * h + 2 + o], _mask(
        [2 * s + k + n for k in (0, 4) for n in (0, 1, 8, 9)]))
        for h in (0, 1) for o in (0, 1) for s in (0, 1)]
    elements = [None] * 8
    for o in (0, 1):
        for s in (0, 1):
            low, high = quads[2 * o + s], quads[4 + 2 * o + s]
            elements[o + 2 * s] = builder.shuffle_vector(low, high, _mask(first))
            elements[o + 2 * s + 4] = builder.shuffle_vector(low, high, _mask(second))
    return elements


def _inside_runs_intrinsic(colour):
    """The intrinsic behind :func:`inside_runs`, for grey (``colour`` False: the colour is
    the opacity) or coloured tables."""

    @intrinsic
    def runs(typingctx, flat, nx, nxy, shift, alpha_tab, color_tab, ds, tstart, tinv,
             threshold, rays, steps):
        def array(value, ndim, dtypes, contiguous=True):
            return (isinstance(value, types.Array) and value.ndim == ndim
                    and value.dtype in dtypes and (value.layout == "C" or not contiguous))

        if not (array(flat, 1, (types.float32, types.float64))
                and array(alpha_tab, 1, (types.float64,))
                and array(color_tab, 2, (types.float64,))
                and array(rays, 2, (types.float64,)) and array(steps, 2, (types.int64,))
                and all(isinstance(n, types.Integer) for n in (nx, nxy, shift))
                and all(isinstance(x, types.Float) for x in (ds, tstart, tinv, threshold))):
            return None

        def codegen(context, builder, signature, args):
            (flat_v, nx_v, nxy_v, shift_v, alpha_v, color_v, ds_v, tstart_v, tinv_v,
             threshold_v, rays_v, steps_v) = args
            sig = signature.args
            f64, i64, i1 = ir.DoubleType(), ir.IntType(64), ir.IntType(1)
            floats, ints = ir.VectorType(f64, LANES), ir.VectorType(i64, LANES)
            masks = ir.VectorType(i1, LANES)
            volume = context.make_array(sig[0])(context, builder, flat_v)
            alpha_tab = context.make_array(sig[4])(context, builder, alpha_v)
            color_tab = context.make_array(sig[5])(context, builder, color_v)
            ray_data = context.make_array(sig[10])(context, builder, rays_v).data
            step_data = context.make_array(sig[11])(context, builder, steps_v).data
            stored = context.get_data_type(sig[0].dtype)

            def scalar(value, index):  # an integer argument as intp, a float as float64
                target = types.float64 if isinstance(sig[index], types.Float) else types.intp
                return context.cast(builder, value, sig[index], target)

            def constant(value, vector_type):
                return ir.Constant(vector_type, [value] * LANES)

            def load(pointer):
                return builder.load(pointer, align=8)

            ax, ay, az, bx, by, bz = (load(_row(builder, ray_data, row, f64))
                                      for row in (AX, AY, AZ, BX, BY, BZ))
            k0 = load(_row(builder, step_data, K, i64))
            end = load(_row(builder, step_data, END, i64))
            acc0 = [load(_row(builder, ray_data, row, f64)) for row in (RED, GREEN, BLUE, ALPHA)]
            ds = _splat(builder, scalar(ds_v, 6), floats)
            tstart = _splat(builder, scalar(tstart_v, 7), floats)
            tinv = _splat(builder, scalar(tinv_v, 8), floats)
            threshold = _splat(builder, scalar(threshold_v, 9), floats)
            row_step = _splat(builder, scalar(nx_v, 1), ints)
            plane_step = _splat(builder, scalar(nxy_v, 2), ints)
            shift = _splat(builder, scalar(shift_v, 3), ints)
            entries = builder.extract_value(alpha_tab.shape, 0)
            last_f = _splat(builder, builder.sitofp(builder.sub(entries, i64(1)), f64), floats)
            last_i = _splat(builder, builder.sub(entries, i64(2)), ints)
            zero_f, one_f = constant(0.0, floats), constant(1.0, floats)
            zero_i, one_i = constant(0, ints), constant(1, ints)
            volume_start = _splat(builder, builder.ptrtoint(volume.data, i64), ints)

            any_lane = cgutils.get_or_insert_function(
                builder.module, ir.FunctionType(i1, [masks]), f"llvm.vector.reduce.or.v{LANES}i1")

            before = builder.block
            loop = builder.append_basic_block("runs.loop")
            done = builder.append_basic_block("runs.done")
            active0 = builder.icmp_signed("<", k0, end)
            builder.cbranch(builder.call(any_lane, [active0]), loop, done)

            builder.position_at_end(loop)
            # Two counts per lane. ``k`` is the lane's own: it stops where the ray turns
            # opaque (what the scalar loop leaves). ``reach`` is the sample the loads take:
            # it runs on to the run's end whatever the compositing found, so that no load
            # waits on the sample before it (the opacity test closed the chain from one
            # sample's loads to the next's; the loads of several samples now overlap). A
            # lane that has turned opaque loads on, inside its run, while other lanes
            # composite; what it loads is not used.
            k = builder.phi(ints)
            reach = builder.phi(ints)
            live = builder.phi(masks)  # reach < end
            clear = builder.phi(masks)  # not yet opaque
            acc = [builder.phi(floats) for _ in range(4)]
            for phi, start in zip((k, reach, live, clear, *acc),
                                  (k0, k0, active0, ir.Constant(masks, [1] * LANES), *acc0),
                                  strict=True):
                phi.add_incoming(start, before)
            active = builder.and_(live, clear)
            # The sample's index position (the lattice: a + ((k + 1/2) ds) b), its cell and
            # fractions (floor: positions inside the volume are >= 0).
            t = builder.fmul(builder.fadd(builder.sitofp(reach, floats), constant(0.5, floats)),
                             ds)
            u = [builder.fadd(a, builder.fmul(t, b)) for a, b in ((ax, bx), (ay, by), (az, bz))]
            cell = [builder.fptosi(value, ints) for value in u]
            tx, ty, tz = (builder.fsub(u[axis], builder.sitofp(cell[axis], floats))
                          for axis in range(3))
            size = context.get_abi_sizeof(stored)
            base = builder.sub(builder.add(builder.add(builder.mul(cell[2], plane_step),
                                                       builder.mul(cell[1], row_step)),
                                           cell[0]), shift)

            # Ask for the cells of the samples PREFETCH_AHEAD steps on: four cache lines a
            # lane (the cell's two rows in its two planes). A ray's next cells lie on new
            # lines that no hardware prefetcher foresees; without this, a packet waits for
            # memory at each (256^3 float32: 105 against 145 M samples/s on one thread).
            ahead_k = builder.sitofp(builder.add(reach, constant(PREFETCH_AHEAD, ints)), floats)
            ahead_t = builder.fmul(builder.fadd(ahead_k, constant(0.5, floats)), ds)
            ahead = builder.sub(builder.add(builder.add(
                builder.mul(builder.fptosi(builder.fadd(az, builder.fmul(ahead_t, bz)), ints),
                            plane_step),
                builder.mul(builder.fptosi(builder.fadd(ay, builder.fmul(ahead_t, by)), ints),
                            row_step)),
                builder.fptosi(builder.fadd(ax, builder.fmul(ahead_t, bx)), ints)), shift)
            ahead_address = builder.add(volume_start, builder.mul(ahead, constant(size, ints)))
            line_offsets = [builder.mul(builder.extract_element(offset, _I32(0)), i64(size))
                            for offset in (zero_i, row_step, plane_step,
                                           builder.add(row_step, plane_step))]
            byte_pointer = ir.IntType(8).as_pointer()
            prefetch = cgutils.get_or_insert_function(
                builder.module, ir.FunctionType(ir.VoidType(), [byte_pointer, _I32, _I32, _I32]),
                "llvm.prefetch.p0")
            for lane in range(LANES):
                address = builder.extract_element(ahead_address, _I32(lane))
                for line in line_offsets:
                    builder.call(prefetch, [builder.inttoptr(builder.add(address, line),
                                                             byte_pointer),
                                            _I32(0), _I32(3), _I32(1)])  # read, keep, data
            both = builder.add(plane_step, row_step)
            # A cell's two neighbours along x lie side by side: one load of the pair per lane
            # and row of the cell, transposed (a lane that is not live loads the first cell).
            safe = builder.select(live, base, zero_i)
            d = []
            for offset in (zero_i, row_step, plane_step, both):
                index = builder.add(safe, offset)
                d += _transposed(builder, [builder.load(builder.bitcast(
                    builder.gep(volume.data, [builder.extract_element(index, _I32(lane))]),
                    ir.VectorType(stored, 2).as_pointer()), align=size) for lane in range(LANES)])

            def widen(value):
                return value if stored == f64 else builder.fpext(value, floats)

            def lerp_stored(a, b, w):  # the difference in the stored type, as numba's
                return builder.fadd(widen(a), builder.fmul(w, widen(builder.fsub(b, a))))

            def lerp(a, b, w):
                return builder.fadd(a, builder.fmul(w, builder.fsub(b, a)))

            # Along x, then y, then z (lerp_corners).
            c0 = lerp(lerp_stored(d[0], d[1], tx), lerp_stored(d[2], d[3], tx), ty)
            c1 = lerp(lerp_stored(d[4], d[5], tx), lerp_stored(d[6], d[7], tx), ty)
            value = lerp(c0, c1, tz)
            # The table's row and weight (lookup), and the segment's opacity (entry).
            x = builder.fmul(builder.fsub(value, tstart), tinv)
            positive = builder.fcmp_ordered(">", x, zero_f)
            beyond = builder.fcmp_ordered(">=", x, last_f)
            floor = builder.fptosi(builder.select(positive, x, zero_f), ints)
            row = builder.select(positive, builder.select(beyond, last_i, floor), zero_i)
            weight = builder.select(positive, builder.select(
                beyond, one_f, builder.fsub(x, builder.sitofp(floor, floats))), zero_f)
            # A row and the next side by side: one load per lane (every lane's row lies in
            # the table, a lane that is not live reads row 0), transposed.
            left, right = _transposed(builder, [builder.load(builder.bitcast(
                builder.gep(alpha_tab.data, [builder.extract_element(row, _I32(lane))]),
                ir.VectorType(f64, 2).as_pointer()), align=8) for lane in range(LANES)])
            alpha = builder.fadd(left, builder.fmul(weight, builder.fsub(right, left)))
            # Front to back over (eqs 1.7-1.8) where the segment is not transparent.
            take = builder.and_(active, builder.fcmp_ordered(">", alpha, zero_f))
            remaining = builder.fsub(one_f, acc[3])
            if colour:
                # The (n, 3) table's row and the next, six floats side by side: per lane one
                # load of four and one of two, transposed.
                def rows(first, count):
                    return _transposed(builder, [builder.load(builder.bitcast(builder.gep(
                        color_tab.data, [builder.add(builder.mul(builder.extract_element(
                            row, _I32(lane)), i64(3)), i64(first))]),
                        ir.VectorType(f64, count).as_pointer()), align=8)
                        for lane in range(LANES)])

                r0, g0, b0, r1 = rows(0, 4)
                g1, b1 = rows(4, 2)
                colours = [builder.fadd(lo, builder.fmul(weight, builder.fsub(hi, lo)))
                           for lo, hi in ((r0, r1), (g0, g1), (b0, b1))]
                over = [builder.fadd(acc[c], builder.fmul(remaining, colours[c]))
                        for c in range(3)]
            else:
                red = builder.fadd(acc[0], builder.fmul(remaining, alpha))
                over = [red, red, red]
            over.append(builder.fadd(acc[3], builder.fmul(remaining, alpha)))
            acc_next = [builder.select(take, new, old) for new, old in zip(over, acc,
                                                                           strict=True)]
            k_next = builder.select(active, builder.add(k, one_i), k)
            opaque = builder.and_(take, builder.fcmp_ordered(">=", acc_next[3], threshold))
            clear_next = builder.and_(clear, builder.not_(opaque))
            reach_next = builder.select(live, builder.add(reach, one_i), reach)
            live_next = builder.and_(live, builder.icmp_signed("<", reach_next, end))
            for phi, value in zip((k, reach, live, clear, *acc),
                                  (k_next, reach_next, live_next, clear_next, *acc_next),
                                  strict=True):
                phi.add_incoming(value, loop)
            builder.cbranch(builder.call(any_lane, [builder.and_(live_next, clear_next)]), loop,
                            done)

            builder.position_at_end(done)
            results = []
            for start, last in zip((k0, *acc0), (k_next, *acc_next), strict=True):
                phi = builder.phi(start.type)
                phi.add_incoming(start, before)
                phi.add_incoming(last, loop)
                results.append(phi)
            builder.store(results[0], _row(builder, step_data, K, i64), align=8)
            for row_index, value in zip((RED, GREEN, BLUE, ALPHA), results[1:], strict=True):
                builder.store(value, _row(builder, ray_data, row_index, f64), align=8)
            return context.get_dummy_value()

        return types.none(flat, nx, nxy, shift, alpha_tab, color_tab, ds, tstart, tinv,
                          threshold, rays, steps), codegen

    return runs


def _inside_runs_lanes(flat, nx, nxy, shift, alpha_tab, color_tab, colour, ds, tstart, tinv,
                       threshold, rays, steps):
    """:func:`inside_runs` one lane at a time (without the JIT): the scalar loop."""
    n = alpha_tab.shape[0]
    for lane in range(LANES):
        k, end = int(steps[K, lane]), int(steps[END, lane])
        r, g, b, a = (float(rays[row, lane]) for row in (RED, GREEN, BLUE, ALPHA))
        while k < end:
            t = (k + 0.5) * ds
            u = [float(rays[AX + axis, lane] + t * rays[BX + axis, lane]) for axis in range(3)]
            cell = [int(value) for value in u]
            base = cell[2] * nxy + cell[1] * nx + cell[0] - shift
            c = [flat[base + offset] for offset in
                 (0, 1, nx, nx + 1, nxy, nxy + 1, nxy + nx, nxy + nx + 1)]
            f = [u[axis] - cell[axis] for axis in range(3)]
            x = [float(c[i]) + f[0] * float(c[i + 1] - c[i]) for i in (0, 2, 4, 6)]
            c0, c1 = x[0] + f[1] * (x[1] - x[0]), x[2] + f[1] * (x[3] - x[2])
            position = (c0 + f[2] * (c1 - c0) - tstart) * tinv
            if not position > 0.0:
                i, w = 0, 0.0
            elif position >= n - 1:
                i, w = n - 2, 1.0
            else:
                i = int(position)
                w = position - i
            alpha = alpha_tab[i] + w * (alpha_tab[i + 1] - alpha_tab[i])
            k += 1
            if alpha > 0.0:
                remaining = 1.0 - a
                if colour is None:
                    r += remaining * alpha
                    g = b = r
                else:
                    r, g, b = (acc + remaining * (color_tab[i, ch] + w * (
                        color_tab[i + 1, ch] - color_tab[i, ch])) for ch, acc in
                        enumerate((r, g, b)))
                a += remaining * alpha
                if a >= threshold:
                    break
        steps[K, lane] = k
        for row, value in zip((RED, GREEN, BLUE, ALPHA), (r, g, b, a), strict=True):
            rays[row, lane] = value


_runs_grey = _inside_runs_intrinsic(colour=False)
_runs_colour = _inside_runs_intrinsic(colour=True)


@jit(inline="always")
def _inside_runs_compiled(flat, nx, nxy, shift, alpha_tab, color_tab, colour, ds, tstart,
                          tinv, threshold, rays, steps):
    if colour is None:
        _runs_grey(flat, nx, nxy, shift, alpha_tab, color_tab, ds, tstart, tinv, threshold,
                   rays, steps)
    else:
        _runs_colour(flat, nx, nxy, shift, alpha_tab, color_tab, ds, tstart, tinv, threshold,
                     rays, steps)


inside_runs = _inside_runs_lanes if numba.config.DISABLE_JIT else _inside_runs_compiled
"""``inside_runs(flat, nx, nxy, shift, alpha_tab, color_tab, colour, ds, tstart, tinv,
threshold, rays, steps)``: ``LANES`` rays' runs of samples inside the volume at once.

Lane ``l`` takes samples ``k = steps[K, l]`` up to ``steps[END, l]`` (none where they are
equal: an idle lane) of the ray at index positions ``a + ((k + 1/2) ds) b`` (``a`` and ``b``
in rows ``AX..AZ`` and ``BX..BZ`` of ``rays``), every one in a cell whose eight corners lie in
``flat`` (a raveled ``[z, y, x]`` volume or brick, float32 or float64, rows of ``nx`` samples,
planes of ``nxy``, global flat index minus ``shift``). Each sample's value is classified by the
table ``alpha_tab`` over ``(value - tstart) tinv`` (and colour from the C-contiguous
``(n, 3)`` ``color_tab``'s rows where ``colour`` is True; where it is None the colour is
the opacity, and the kernel is compiled without the colour's loads; both tables of at least
2 rows), and composited front to back onto rows ``RED..ALPHA``, until the lane's opacity
reaches ``threshold``. On return ``steps[K]`` holds
each lane's next sample and ``rays`` its colour and opacity."""


def _warp_octet_intrinsic(colour, channels):
    """The intrinsic behind :func:`vrlib._kernels.shear.warp_octet`, for grey (``colour``
    False: red alone is interpolated and copied to green and blue) or coloured images of
    ``channels`` channels (opacity the last)."""

    @intrinsic
    def octet(typingctx, src, n_i, n_j, out, at_out, c0, mx, ax, my, ay):
        if not (all(isinstance(a, types.Array) and a.ndim == 1 and a.layout == "C"
                    and a.dtype == types.float64 for a in (src, out)) and out.mutable
                and all(isinstance(n, types.Integer) for n in (n_i, n_j, at_out, c0))
                and all(isinstance(x, types.Float) for x in (mx, ax, my, ay))):
            return None

        def codegen(context, builder, signature, args):
            sig = signature.args
            f64, i64 = ir.DoubleType(), ir.IntType(64)
            floats, ints = ir.VectorType(f64, LANES), ir.VectorType(i64, LANES)

            def scalar(index):  # an integer argument as intp, a float as float64
                target = types.float64 if isinstance(sig[index], types.Float) else types.intp
                return context.cast(builder, args[index], sig[index], target)

            def splat_f(value):
                return _splat(builder, value, floats)

            def splat_i(value):
                return _splat(builder, value, ints)

            source = context.make_array(sig[0])(context, builder, args[0])
            image = context.make_array(sig[3])(context, builder, args[3])
            n_i, n_j = scalar(1), scalar(2)
            # Each lane's pixel column and where its ray meets the intermediate image, as the
            # scalar warp computes them: x = mx c + ax, y = my c + ay.
            column = builder.add(splat_i(scalar(5)), ir.Constant(ints, list(range(LANES))))
            c = builder.sitofp(column, floats)
            x = builder.fadd(builder.fmul(splat_f(scalar(6)), c), splat_f(scalar(7)))
            y = builder.fadd(builder.fmul(splat_f(scalar(8)), c), splat_f(scalar(9)))
            zero_f = ir.Constant(floats, [0.0] * LANES)
            one_f = ir.Constant(floats, [1.0] * LANES)
            last_i = splat_f(builder.sitofp(builder.sub(n_i, i64(1)), f64))
            last_j = splat_f(builder.sitofp(builder.sub(n_j, i64(1)), f64))
            inside = builder.and_(
                builder.and_(builder.fcmp_ordered(">=", x, zero_f),
                             builder.fcmp_ordered(">=", y, zero_f)),
                builder.and_(builder.fcmp_ordered("<=", x, last_i),
                             builder.fcmp_ordered("<=", y, last_j)))
            # The cell (min(int(x), n_i - 2), likewise for y) of the lanes inside; 0 elsewhere.
            def cell(u, n):
                whole = builder.fptosi(builder.select(inside, u, zero_f), ints)
                top = splat_i(builder.sub(n, i64(2)))
                return builder.select(builder.icmp_signed("<", top, whole), top, whole)

            i, j = cell(x, n_i), cell(y, n_j)
            tx = builder.fsub(x, builder.sitofp(i, floats))
            ty = builder.fsub(y, builder.sitofp(j, floats))
            # A pixel's two neighbours along a row, every channel, lie side by side: one
            # load of 2 * channels floats per lane and row, transposed into one vector per
            # corner and channel (a lane outside the image loads the first cell, n_i and
            # n_j being at least 2, and is masked below).
            row = builder.mul(n_i, i64(channels))
            base = builder.mul(builder.add(builder.mul(j, splat_i(n_i)), i),
                               splat_i(i64(channels)))
            block = ir.VectorType(f64, 2 * channels)

            def neighbours(offset):  # per element of the block, its LANES lanes
                return _transposed(builder, [builder.load(builder.bitcast(builder.gep(
                    source.data, [builder.add(builder.extract_element(base, _I32(lane)),
                                              offset)]), block.as_pointer()), align=8)
                    for lane in range(LANES)])

            top, bottom = neighbours(i64(0)), neighbours(row)

            def corners(channel):  # (j, i), (j, i + 1), (j + 1, i), (j + 1, i + 1)
                return [top[channel], top[channels + channel], bottom[channel],
                        bottom[channels + channel]]

            def clipped(value):  # min(max(value, 0.0), 1.0), as numba's min and max select
                value = builder.select(builder.fcmp_ordered(">", zero_f, value), zero_f, value)
                return builder.select(builder.fcmp_ordered("<", one_f, value), one_f, value)

            wx, wy = builder.fsub(one_f, tx), builder.fsub(one_f, ty)

            def bilinear(d):
                top = builder.fadd(builder.fmul(wx, d[0]), builder.fmul(tx, d[1]))
                bottom = builder.fadd(builder.fmul(wx, d[2]), builder.fmul(tx, d[3]))
                return clipped(builder.fadd(builder.fmul(wy, top), builder.fmul(ty, bottom)))

            a = corners(channels - 1)  # opacity: the last channel
            # Transparent where all four neighbours are (colours are premultiplied).
            clear = builder.and_(
                builder.and_(builder.fcmp_ordered("==", a[0], zero_f),
                             builder.fcmp_ordered("==", a[1], zero_f)),
                builder.and_(builder.fcmp_ordered("==", a[2], zero_f),
                             builder.fcmp_ordered("==", a[3], zero_f)))
            seen = builder.and_(inside, builder.not_(clear))
            red = bilinear(corners(0))
            green, blue = ((bilinear(corners(1)), bilinear(corners(2)))
                           if colour else (red, red))
            pixel = [builder.select(seen, value, zero_f)
                     for value in (red, green, blue, bilinear(a))]
            # Interleaved into the pixels' (r, g, b, a), one store of 4 LANES floats.
            pairs = [(lane, lane + LANES) for lane in range(LANES)]
            rg = builder.shuffle_vector(pixel[0], pixel[1], ir.Constant(
                ir.VectorType(_I32, 2 * LANES), [n for pair in pairs for n in pair]))
            ba = builder.shuffle_vector(pixel[2], pixel[3], ir.Constant(
                ir.VectorType(_I32, 2 * LANES), [n for pair in pairs for n in pair]))
            order = [n for lane in range(LANES)
                     for n in (2 * lane, 2 * lane + 1, 2 * LANES + 2 * lane,
                               2 * LANES + 2 * lane + 1)]
            pixels = builder.shuffle_vector(rg, ba, ir.Constant(
                ir.VectorType(_I32, 4 * LANES), order))
            target = builder.gep(image.data, [scalar(4)])
            builder.store(pixels, builder.bitcast(
                target, ir.VectorType(f64, 4 * LANES).as_pointer()), align=8)
            return context.get_dummy_value()

        return types.none(src, n_i, n_j, out, at_out, c0, mx, ax, my, ay), codegen

    return octet


#: Grey images of red and opacity, or of four channels; coloured images.
warp_octet_grey_pairs = _warp_octet_intrinsic(colour=False, channels=2)
warp_octet_grey = _warp_octet_intrinsic(colour=False, channels=4)
warp_octet_colour = _warp_octet_intrinsic(colour=True, channels=4)
