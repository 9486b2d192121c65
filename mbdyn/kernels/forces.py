"""Force elements: springs, dampers, bushings, bearings and contact, as body wrenches.

Each element adds forces at world points and moments to the per-frame applied loads ``F``,
``N`` (world components, reduced to each centre of mass) that gravity and point loads fill
in ``dynamics.applied_loads``; both formulations (Jourdain and Newton-Euler with reactions)
read them from there, so an element enters every route through one place.  A force that
acts on two frames acts on both with opposite signs at the same world point, so it
transmits no net force or moment to the tree.

Layout (built by ``mbdyn.compiled.force_packing``): ``force_int[e]`` holds ``[kind, frame_a, frame_b,
offset, table1_offset, table1_mode, table2_offset, table2_mode, index1, index2]`` (frame
-1 is the ground); the element's numbers start at ``force_data[offset]``.  A table block
is ``[n, clamp, x(n), y(n), d(n), integral(n)]``: knots, values, slopes at the knots
(piecewise-cubic Hermite, as PCHIP gives them; for linear interpolation only the end
slopes are used, for extrapolation) and the integral of the interpolant from the first
knot to each knot.  Outside the knots a table extrapolates linearly with its end slope,
or holds its end value (``clamp``).

With ``acc`` (two entries) an element also adds its potential energy to ``acc[0]`` and
the power of its non-conservative part (what dampers and friction take out, negative) to
``acc[1]``; with three, the actuators' power goes to ``acc[2]`` instead.
"""
import math

from numba import njit

from .actuation import PROGRAM, PROGRAM_WORK, actuator_effort, program_value, stop_effort
from .contact import CONTACT_SHAPES, record, shape_contacts
from .linalg3 import cross_to, mat_t_vec, mat_vec
from .tables import LINEAR, NO_TABLE, PCHIP, table_eval  # noqa: F401
from .views import UNCOUNTED
from .internal import internal

(SPRING_DAMPER, JOINT_SPRING_DAMPER, BUSHING, BEARING, CONTACT_SPHERE, CONTACT_DISK, ACTUATOR,
 JOINT_STOP) = 1, 2, 3, 4, 5, 6, 7, 8
KIND_CODES = {"spring-damper": SPRING_DAMPER, "joint-spring-damper": JOINT_SPRING_DAMPER,
              "bushing": BUSHING, "bearing": BEARING, "contact": CONTACT_SPHERE,
              "actuator": ACTUATOR, "joint-stop": JOINT_STOP}
LAW = 3          # a law evaluated in Python, given as preload (PROGRAM = 4: compiled)
ROW = 10          # entries of a force_int row
FORCE_WORK = 74 + PROGRAM_WORK   # floats of scratch ``force_elements`` needs


@internal(**UNCOUNTED)
def _point(i, s, R, r, w, v, p, pv, lever):
    """World position ``p`` and velocity ``pv`` of the point ``s`` (frame components) of
    frame ``i``; the ground (-1) holds still and its components are world ones."""
    if i < 0:
        for k in range(3):
            p[k] = s[k]
            pv[k] = 0.0
        return
    mat_vec(R[i], s, lever)
    cross_to(w[i], lever, pv)
    for k in range(3):
        p[k] = r[i, k] + lever[k]
        pv[k] += v[i, k]


@internal(**UNCOUNTED)
def _material_velocity(i, p, r, w, v, out, lever):
    """Velocity of the material point of frame ``i`` at the world point ``p``."""
    if i < 0:
        out[:] = 0.0
        return
    for k in range(3):
        lever[k] = p[k] - r[i, k]
    cross_to(w[i], lever, out)
    for k in range(3):
        out[k] += v[i, k]


@internal(**UNCOUNTED)
def _apply(i, p, f, m, sign, R, r, com, F, N, lever, t):
    """Add ``sign * f`` acting at the world point ``p`` and the moment ``sign * m`` to
    frame ``i``'s loads (reduced to its centre of mass)."""
    if i < 0:
        return
    mat_vec(R[i], com[i], lever)
    for k in range(3):
        lever[k] = p[k] - r[i, k] - lever[k]
    cross_to(lever, f, t)
    for k in range(3):
        F[i, k] += sign * f[k]
        N[i, k] += sign * (t[k] + m[k])


@internal(**UNCOUNTED)
def _law(data, spring_off, spring_mode, damper_off, damper_mode, k, c, F0, x, xd, tmp,
         qfull, ufull, work):
    """Tension of a spring-damper law and the potential of its spring part:
    ``(spring force, damper force, potential)``.  A law given as a program (``PROGRAM``)
    is all spring force, its potential not known (its power counts as non-conservative)."""
    if spring_mode == PROGRAM:
        fs = F0 + program_value(data, spring_off, 0.0, x, xd, qfull, ufull, work)
        V = 0.0
    elif spring_mode == NO_TABLE:
        fs = F0 + k * x
        V = F0 * x + 0.5 * k * x * x
    elif spring_mode == LAW:            # the caller wrote law(x, x') into the preload slot
        fs = F0
        V = 0.0
    else:
        table_eval(data, spring_off, spring_mode, 0.0, tmp)
        V0 = tmp[2]
        table_eval(data, spring_off, spring_mode, x, tmp)
        fs = tmp[0]
        V = tmp[2] - V0
    if damper_mode == NO_TABLE:
        fd = c * xd
    else:
        table_eval(data, damper_off, damper_mode, xd, tmp)
        fd = tmp[0]
    return fs, fd, V


@njit(**UNCOUNTED)
def force_elements(force_int, force_data, parent, axis, com, qfull, ufull, R, r, w, v, F, N,
                   acc, work, shapes):
    """Add every force element's wrenches to ``F``, ``N``; with ``acc.shape[0] >= 2`` also
    their potential energy (``acc[0]``) and non-conservative power (``acc[1]``).
    ``work``: at least ``FORCE_WORK`` floats of scratch.  ``shapes``: None when the table
    has no contact between shapes (``CONTACT_SHAPES``), else True -- a type, so that for
    such a table numba compiles no shape-contact kernel (``kernels.contact``: a third of
    the force kernel, 6 s of a first run)."""
    # long: one branch per force-element kind in one compiled loop: a kernel per kind would be
    # one more compiled entry point per kind and a dispatch per element.
    want = acc.shape[0] >= 2
    tmp, six, prog = work[0:48], work[48:74], work[74:FORCE_WORK]
    pa, pb, va, vb, d, f = tmp[0:3], tmp[3:6], tmp[6:9], tmp[9:12], tmp[12:15], tmp[15:18]
    m, lever, t, e1, e2, tab = tmp[18:21], tmp[21:24], tmp[24:27], tmp[27:30], tmp[30:33], tmp[33:36]
    x6, xd6, w6, ks = six[0:6], six[6:12], six[12:18], six[18:26]
    zero = tmp[36:39]
    zero[:] = 0.0
    for e in range(force_int.shape[0]):
        kind, ia, ib, off = force_int[e, 0], force_int[e, 1], force_int[e, 2], force_int[e, 3]
        if kind == SPRING_DAMPER:
            # data: point_a(3), point_b(3), k, c, free length, preload, regularisation length
            _point(ia, force_data[off:off + 3], R, r, w, v, pa, va, lever)
            _point(ib, force_data[off + 3:off + 6], R, r, w, v, pb, vb, lever)
            k_, c_, L0, F0, eps = (force_data[off + 6], force_data[off + 7],
                                   force_data[off + 8], force_data[off + 9], force_data[off + 10])
            L2 = 0.0
            for q in range(3):
                d[q] = pb[q] - pa[q]
                L2 += d[q] * d[q]
            L = math.sqrt(L2)
            scale = 1.0 / math.sqrt(L2 + eps * eps)     # regularised direction a -> b
            xd = 0.0
            for q in range(3):
                d[q] *= scale
                xd += d[q] * (vb[q] - va[q])
            fs, fd, V = _law(force_data, force_int[e, 4], force_int[e, 5], force_int[e, 6],
                             force_int[e, 7], k_, c_, F0, L - L0, xd, tab, qfull, ufull, prog)
            T = fs + fd                                 # tension pulls a towards b
            for q in range(3):
                f[q] = T * d[q]
            _apply(ia, pa, f, zero, 1.0, R, r, com, F, N, lever, t)
            _apply(ib, pb, f, zero, -1.0, R, r, com, F, N, lever, t)
            if want:
                acc[0] += V
                acc[1] -= (T if force_int[e, 5] >= LAW else fd) * xd
        elif kind == JOINT_SPRING_DAMPER:
            # frame_a: the joint's child frame; index1/index2: joint-space q and u entries;
            # data: rest value, k, c, preload, prismatic (1) or revolute (0)
            i = ia
            kq, ku = force_int[e, 8], force_int[e, 9]
            x = qfull[kq] - force_data[off]
            xd = ufull[ku]
            fs, fd, V = _law(force_data, force_int[e, 4], force_int[e, 5], force_int[e, 6],
                             force_int[e, 7], force_data[off + 1], force_data[off + 2],
                             force_data[off + 3], x, xd, tab, qfull, ufull, prog)
            mat_vec(R[i], axis[i], e2)
            _joint_effort(i, parent[i], e2, force_data[off + 4] != 0.0, -(fs + fd), R, r,
                          com, F, N, e1, pa, zero, lever, t)
            if want:
                acc[0] += V
                acc[1] -= ((fs + fd) if force_int[e, 5] >= LAW else fd) * xd
        elif kind == ACTUATOR or kind == JOINT_STOP:
            # frame_a: the joint's child frame; index1/index2: joint-space q and u entries
            i = ia
            x, xd = qfull[force_int[e, 8]], ufull[force_int[e, 9]]
            mat_vec(R[i], axis[i], e2)
            if kind == ACTUATOR:
                tau = actuator_effort(force_data, off, force_int[e], x, xd, qfull, ufull, i,
                                      com, R, r, e2, prog)
                if want:        # what it puts in: apart in acc[2] when asked
                    acc[2 if acc.shape[0] >= 3 else 1] += tau * xd
                prismatic = force_data[off + 1] != 0.0
            else:
                tau = stop_effort(force_data, off, x, xd, acc, want)
                prismatic = force_data[off + 4] != 0.0
            _joint_effort(i, parent[i], e2, prismatic, tau, R, r, com, F, N, e1, pa, zero,
                          lever, t)
        elif kind == BUSHING:
            # data: point_a(3), point_b(3), K (6x6 row-major), C (6x6), all in frame a's
            # axes; x = (translation, small rotation) of b relative to a
            _point(ia, force_data[off:off + 3], R, r, w, v, pa, va, lever)
            _point(ib, force_data[off + 3:off + 6], R, r, w, v, pb, vb, lever)
            for q in range(3):
                d[q] = pb[q] - pa[q]
            _bushing_state(ia, ib, R, w, d, va, vb, x6, xd6, lever, t, e1, e2)
            for row in range(6):
                s_ = 0.0
                for col in range(6):
                    s_ += force_data[off + 6 + 6 * row + col] * x6[col] \
                        + force_data[off + 42 + 6 * row + col] * xd6[col]
                w6[row] = -s_
            _to_world(ia, R, w6[0:3], f)
            _to_world(ia, R, w6[3:6], m)
            _apply(ib, pb, f, m, 1.0, R, r, com, F, N, lever, t)
            _apply(ia, pb, f, m, -1.0, R, r, com, F, N, lever, t)
            if want:
                _material_velocity(ia, pb, r, w, v, va, lever)
                P = 0.0
                for q in range(3):
                    P += f[q] * (vb[q] - va[q])
                    P += m[q] * ((w[ib, q] if ib >= 0 else 0.0) - (w[ia, q] if ia >= 0 else 0.0))
                acc[1] += P
        elif kind == BEARING:
            # data: shaft point (shaft frame a), centre (housing frame b), e1, e2 (housing
            # axes), 8 constant coefficients kxx kxy kyx kyy cxx cxy cyx cyy, 8 table offsets
            # (-1: constant); index1: joint-space speed entry of the spin (-1: none)
            _point(ia, force_data[off:off + 3], R, r, w, v, pa, va, lever)
            _point(ib, force_data[off + 3:off + 6], R, r, w, v, pb, vb, lever)
            _to_world(ib, R, force_data[off + 6:off + 9], e1)
            _to_world(ib, R, force_data[off + 9:off + 12], e2)
            _material_velocity(ib, pa, r, w, v, vb, lever)
            spin = ufull[force_int[e, 8]] if force_int[e, 8] >= 0 else 0.0
            for c8 in range(8):
                toff = int(force_data[off + 20 + c8])
                if toff < 0:
                    ks[c8] = force_data[off + 12 + c8]
                else:
                    table_eval(force_data, toff, force_int[e, 5], spin, tab)
                    ks[c8] = tab[0]
            xx, yy, xd, yd = 0.0, 0.0, 0.0, 0.0
            for q in range(3):
                d[q] = pa[q] - pb[q]
                xx += e1[q] * d[q]
                yy += e2[q] * d[q]
                xd += e1[q] * (va[q] - vb[q])
                yd += e2[q] * (va[q] - vb[q])
            fx = -(ks[0] * xx + ks[1] * yy + ks[4] * xd + ks[5] * yd)
            fy = -(ks[2] * xx + ks[3] * yy + ks[6] * xd + ks[7] * yd)
            for q in range(3):
                f[q] = fx * e1[q] + fy * e2[q]
            _apply(ia, pa, f, zero, 1.0, R, r, com, F, N, lever, t)
            _apply(ib, pa, f, zero, -1.0, R, r, com, F, N, lever, t)
            if want:
                P = 0.0
                for q in range(3):
                    P += f[q] * (va[q] - vb[q])
                acc[1] += P
        elif kind == CONTACT_SHAPES:       # between shapes: kernels/contact.py
            if shapes is not None:
                shape_contacts(off, force_data, R, r, w, v, com, F, N, acc, want,
                               work[FORCE_WORK:])
        else:
            _contact(kind, ia, off, force_data, R, r, w, v, com, F, N, acc, want,
                     pa, va, d, f, lever, t, e1, zero)


@internal(**UNCOUNTED)
def _joint_effort(i, p, e, prismatic, tau, R, r, com, F, N, f, at, zero, lever, t):
    """The effort ``tau`` on the coordinate of joint ``i`` (parent ``p``; ``e`` its axis in
    world components): a force along a prismatic axis or a moment about a revolute one, on
    the child and, opposite, on the parent, at the joint's origin (``f``: scratch)."""
    for q in range(3):
        f[q] = tau * e[q]
        at[q] = r[i, q]
    if prismatic:
        _apply(i, at, f, zero, 1.0, R, r, com, F, N, lever, t)
        _apply(p, at, f, zero, -1.0, R, r, com, F, N, lever, t)
    else:
        _apply(i, at, zero, f, 1.0, R, r, com, F, N, lever, t)
        _apply(p, at, zero, f, -1.0, R, r, com, F, N, lever, t)


@internal(**UNCOUNTED)
def _to_world(i, R, s, out):
    if i < 0:
        for k in range(3):      # element-wise: an array assignment compiles numba's message
            out[k] = s[k]
    else:
        mat_vec(R[i], s, out)


@internal(**UNCOUNTED)
def _bushing_state(ia, ib, R, w, d, va, vb, x6, xd6, t1, t2, t3, t4):
    """Relative translation and small rotation of frame b in frame a's axes, and their
    rates (``d`` = world offset b - a; ``va``, ``vb`` the points' velocities)."""
    # translation and its rate: x = Ra^T d, x' = Ra^T (vb - va) - wa_a x x
    for q in range(3):
        t1[q] = vb[q] - va[q]
    if ia >= 0:
        mat_t_vec(R[ia], d, t2)
        mat_t_vec(R[ia], t1, t3)
        mat_t_vec(R[ia], w[ia], t4)
        cross_to(t4, t2, t1)
        for q in range(3):
            x6[q] = t2[q]
            xd6[q] = t3[q] - t1[q]
    else:
        for q in range(3):
            x6[q] = d[q]
            xd6[q] = t1[q]
    # rotation: axial vector of the skew part of Rrel = Ra^T Rb; rate: Ra^T (wb - wa)
    for a_ in range(3):
        b_, c_ = (a_ + 1) % 3, (a_ + 2) % 3
        # Rrel[c_, b_] - Rrel[b_, c_]
        s_ = 0.0
        for q in range(3):
            ra_c = R[ia, q, c_] if ia >= 0 else (1.0 if q == c_ else 0.0)
            ra_b = R[ia, q, b_] if ia >= 0 else (1.0 if q == b_ else 0.0)
            rb_b = R[ib, q, b_] if ib >= 0 else (1.0 if q == b_ else 0.0)
            rb_c = R[ib, q, c_] if ib >= 0 else (1.0 if q == c_ else 0.0)
            s_ += ra_c * rb_b - ra_b * rb_c
        x6[3 + a_] = 0.5 * s_
    for q in range(3):
        t1[q] = (w[ib, q] if ib >= 0 else 0.0) - (w[ia, q] if ia >= 0 else 0.0)
    if ia >= 0:
        mat_t_vec(R[ia], t1, t2)
    else:
        for q in range(3):
            t2[q] = t1[q]
    for q in range(3):
        xd6[3 + q] = t2[q]


@internal(**UNCOUNTED)
def _contact(kind, i, off, data, R, r, w, v, com, F, N, acc, want, pc, vc, n, f, lever, t,
             ax, zero):
    """Compliant contact of a sphere (or a disk's rim) of frame ``i`` with a plane fixed
    in the world.  data: centre (frame components), radius, plane point (3), unit normal
    (3), k, exponent, Hunt-Crossley damping factor, friction coefficient, regularising
    speed, [disk axis (frame components) for a rim]."""
    radius = data[off + 3]
    for q in range(3):
        n[q] = data[off + 7 + q]
    mat_vec(R[i], data[off:off + 3], lever)
    for q in range(3):
        pc[q] = r[i, q] + lever[q]                     # the sphere's or disk's centre
    if kind == CONTACT_DISK:
        # the rim's point nearest the plane: centre + radius * (part of -n across the axis)
        mat_vec(R[i], data[off + 15:off + 18], ax)
        na = n[0] * ax[0] + n[1] * ax[1] + n[2] * ax[2]
        s2 = 0.0
        for q in range(3):
            lever[q] = -n[q] + na * ax[q]
            s2 += lever[q] * lever[q]
        sc = radius / math.sqrt(s2 + 1e-24)
        for q in range(3):
            pc[q] += sc * lever[q]
    else:
        for q in range(3):
            pc[q] -= radius * n[q]                     # the sphere's lowest point
    dist = 0.0
    for q in range(3):
        dist += (pc[q] - data[off + 4 + q]) * n[q]
    delta = -dist
    if delta <= 0.0:
        return
    _material_velocity(i, pc, r, w, v, vc, lever)
    vn = vc[0] * n[0] + vc[1] * n[1] + vc[2] * n[2]
    delta_dot = -vn
    k_, ex, chc, mu, veps = (data[off + 10], data[off + 11], data[off + 12], data[off + 13],
                             data[off + 14])
    elastic = k_ * delta ** ex
    fn = elastic * (1.0 + chc * delta_dot)
    if fn < 0.0:                                       # no pull: the surfaces separate
        fn = 0.0
    vt2 = 0.0
    for q in range(3):
        lever[q] = vc[q] - vn * n[q]                    # sliding velocity
        vt2 += lever[q] * lever[q]
    ft = -mu * fn / math.sqrt(vt2 + veps * veps)
    for q in range(3):
        f[q] = fn * n[q] + ft * lever[q]
    _apply(i, pc, f, zero, 1.0, R, r, com, F, N, lever, t)
    if want:
        record(acc, pc, f)
        acc[0] += k_ * delta ** (ex + 1.0) / (ex + 1.0)
        P = 0.0
        for q in range(3):
            P += f[q] * vc[q]
        acc[1] += P + elastic * delta_dot
