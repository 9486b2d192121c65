"""Contact between shapes attached to bodies: the broad phase, the narrow phase of each
supported pair of shape kinds, and the compliant force law (Hunt-Crossley normal force,
regularised Coulomb friction), as wrenches on the per-frame loads ``F``, ``N``.

One contact element is one row of the force table (kind ``CONTACT_SHAPES``; see
``kernels.forces``), its numbers at ``data[off:]`` (written by
``mbdyn.compiled.contact_packing``):

* header (``HEADER`` floats): number of shapes, number of listed pairs, mode
  (``PAIRS``: the listed pairs; ``SWEEP``: every pair of the shapes, found by
  sweep-and-prune; ``ALL``: every pair tested), stiffness ``k``, exponent ``n``,
  Hunt-Crossley damping factor per unit speed, friction coefficient, slip speed;
* a record of ``SREC`` floats per shape: kind, frame (-1 the ground), position (frame
  axes), ``C`` (3x3 row-major: the shape's local axes in the frame's axes, as columns),
  bounding radius, three sizes, the offset of a cam's profile block;
* the listed pairs, two shape indices each;
* each cam's profile block ``[n, knots (n+1), (x_k, y_k) (2n), cubic coefficients (4n)]``:
  a periodic cubic spline ``r(phi)`` (``phi`` from the shape's local x towards its local y).

Shapes (local axes): a sphere (radius); a plane (a half-space of its body: the solid on the
side of ``-z``, outward normal local ``z``); a box (half sizes along x, y, z); a capsule and
a cylinder (radius, half length along ``z``); a cam (the profile in the local x-y plane,
extruded along ``z``).  The narrow phase of a pair gives contact points ``p`` with a
normal ``n`` from the first shape to the second (in the order of ``KINDS``' codes) and a
signed distance (negative: penetration ``delta = -distance``); a touching point pushes the
second shape along ``n`` and the first along ``-n``, at the same world point, so that the
pair transmits no net force or moment.
"""
import math

from numba import njit

from .contact_geometry import (FAR, axis, cam_flat, cam_roller, corner, plane_point, pose,
                               segment_point, segments, sphere_box, spheres)
from .views import UNCOUNTED
from .internal import internal

#: the force-table kind code of a contact element between shapes (apart from the codes
#: kernels.forces lists, which are small integers)
CONTACT_SHAPES = 20
SPHERE, PLANE, BOX, CAPSULE, CYLINDER, CAM = 1, 2, 3, 4, 5, 6
KINDS = {"sphere": SPHERE, "plane": PLANE, "box": BOX, "capsule": CAPSULE,
         "cylinder": CYLINDER, "cam": CAM}
PAIRS, SWEEP, ALL = 0, 1, 2
HEADER = 10
SREC = 20
#: floats of scratch a contact element needs: this plus ``6`` per shape of a group
CONTACT_WORK = 64
#: where the records of touching points start in an ``acc`` long enough to hold them
RECORDS = 4


# ---------------------------------------------------------------- the force law
@internal(**UNCOUNTED)
def _touch(ia, ib, p, n, dist, off, data, R, r, w, v, com, F, N, acc, want, t):
    """The force of one contact point: ``dist < 0`` pushes frame ``ib`` along ``n`` and
    frame ``ia`` along ``-n`` at the world point ``p``; energy and power into ``acc``."""
    if dist >= 0.0:
        return
    va, vb, vt, f = t[0:3], t[3:6], t[6:9], t[9:12]
    _velocity(ia, p, r, w, v, va)
    _velocity(ib, p, r, w, v, vb)
    vn = 0.0
    for q in range(3):
        vb[q] -= va[q]                          # relative velocity of b's point to a's
        vn += vb[q] * n[q]
    delta = -dist
    k_, ex, chc, mu, veps = (data[off + 3], data[off + 4], data[off + 5], data[off + 6],
                             data[off + 7])
    elastic = k_ * delta ** ex
    fn = elastic * (1.0 - chc * vn)             # delta' = -vn
    if fn < 0.0:                                # no pull: the surfaces separate
        fn = 0.0
    vt2 = 0.0
    for q in range(3):
        vt[q] = vb[q] - vn * n[q]
        vt2 += vt[q] * vt[q]
    ft = -mu * fn / math.sqrt(vt2 + veps * veps)
    P = 0.0
    for q in range(3):
        f[q] = fn * n[q] + ft * vt[q]
        P += f[q] * vb[q]
    _apply(ib, p, f, 1.0, R, r, com, F, N, va)
    _apply(ia, p, f, -1.0, R, r, com, F, N, va)
    if want:
        acc[0] += k_ * delta ** (ex + 1.0) / (ex + 1.0)
        acc[1] += P - elastic * vn
        if ib < 0:                              # recorded on the body, not the ground
            for q in range(3):
                f[q] = -f[q]
        record(acc, p, f)


@internal(**UNCOUNTED)
def record(acc, p, f):
    """With ``acc`` longer than ``RECORDS``, the touching point ``p`` and the force ``f``
    on its second body appended there (``acc[3]`` counts them; what does not fit is
    counted, not stored): the contact forces the pictures draw
    (``algorithms.contacts.contact_forces``)."""
    if acc.shape[0] <= RECORDS:
        return
    k = int(acc[3])
    at = RECORDS + 6 * k
    if at + 6 <= acc.shape[0]:
        for q in range(3):
            acc[at + q] = p[q]
            acc[at + 3 + q] = f[q]
    acc[3] = k + 1


@internal(**UNCOUNTED)
def _velocity(i, p, r, w, v, out):
    """Velocity of the material point of frame ``i`` at the world point ``p``."""
    if i < 0:
        for q in range(3):
            out[q] = 0.0
        return
    lx, ly, lz = p[0] - r[i, 0], p[1] - r[i, 1], p[2] - r[i, 2]
    out[0] = v[i, 0] + w[i, 1] * lz - w[i, 2] * ly
    out[1] = v[i, 1] + w[i, 2] * lx - w[i, 0] * lz
    out[2] = v[i, 2] + w[i, 0] * ly - w[i, 1] * lx


@internal(**UNCOUNTED)
def _apply(i, p, f, sign, R, r, com, F, N, lever):
    """``sign * f`` at the world point ``p`` on frame ``i`` (reduced to its centre of
    mass)."""
    if i < 0:
        return
    for q in range(3):
        lever[q] = p[q] - r[i, q] - (R[i, q, 0] * com[i, 0] + R[i, q, 1] * com[i, 1]
                                     + R[i, q, 2] * com[i, 2])
    F[i, 0] += sign * f[0]
    F[i, 1] += sign * f[1]
    F[i, 2] += sign * f[2]
    N[i, 0] += sign * (lever[1] * f[2] - lever[2] * f[1])
    N[i, 1] += sign * (lever[2] * f[0] - lever[0] * f[2])
    N[i, 2] += sign * (lever[0] * f[1] - lever[1] * f[0])


# ---------------------------------------------------------------- a pair
@internal(**UNCOUNTED)
def pair(s1, s2, off, data, R, r, w, v, com, F, N, acc, want, query, t):
    """The contact of the shapes whose records start at ``s1`` and ``s2``: its forces
    (unless ``query``), and the smallest signed distance of its points (``FAR`` for a pair
    whose kinds have no narrow phase)."""
    if data[s1] > data[s2]:
        s1, s2 = s2, s1
    k1, k2 = int(data[s1]), int(data[s2])
    ia, ib = int(data[s1 + 1]), int(data[s2 + 1])
    c1, c2, A1, A2 = t[0:3], t[3:6], t[6:15], t[15:24]
    p, n, e, g = t[24:27], t[27:30], t[30:33], t[33:36]
    tmp = t[36:60]
    pose(data, s1, R, r, c1, A1)
    pose(data, s2, R, r, c2, A2)
    r1, r2 = data[s1 + 15], data[s2 + 15]
    if k1 == PLANE and (k2 == BOX or k2 == CAPSULE or k2 == CYLINDER):
        axis(A1, 2, g)
        best = FAR
        for k in range(8 if k2 == BOX else 2):
            corner(k2, k, c2, A2, data[s2 + 15:s2 + 18], g, e, n)
            dist = plane_point(e, c1, g, p)
            if not query:
                _touch(ia, ib, p, g, dist, off, data, R, r, w, v, com, F, N, acc, want, tmp)
            best = min(best, dist)
        return best
    if k1 == SPHERE and k2 == SPHERE:
        dist = spheres(c1, r1, c2, r2, p, n)
    elif k1 == SPHERE and k2 == CAPSULE:
        segment_point(c2, A2, data[s2 + 16], c1, e)
        dist = spheres(c1, r1, e, r2, p, n)
    elif k1 == CAPSULE and k2 == CAPSULE:
        segments(c1, A1, data[s1 + 16], c2, A2, data[s2 + 16], g, e, tmp)
        dist = spheres(g, r1, e, r2, p, n)
    elif k1 == SPHERE and k2 == PLANE:         # the plane pushes the sphere out
        axis(A2, 2, g)
        for q in range(3):
            e[q] = c1[q] - r1 * g[q]
            n[q] = -g[q]
        dist = plane_point(e, c2, g, p)
    elif k1 == SPHERE and k2 == BOX:
        dist = sphere_box(c1, r1, c2, A2, data[s2 + 15:s2 + 18], p, n, tmp)
    elif k1 == PLANE and k2 == CAM:
        axis(A1, 2, n)
        dist = cam_flat(c1, n, c2, A2, data, int(data[s2 + 18]), p, e, tmp)
    elif (k1 == SPHERE or k1 == CYLINDER) and k2 == CAM:
        dist = cam_roller(c1, r1, c2, A2, data, int(data[s2 + 18]), p, n, tmp)
    else:
        return FAR
    if not query and dist < FAR:
        _touch(ia, ib, p, n, dist, off, data, R, r, w, v, com, F, N, acc, want, tmp)
    return dist


# ---------------------------------------------------------------- the element
@internal(**UNCOUNTED)
def shape_contacts(off, data, R, r, w, v, com, F, N, acc, want, work):
    """Every touching pair of the contact element at ``data[off]``: its wrenches into
    ``F``, ``N`` and, with ``want``, its energy and power into ``acc``.  ``work``:
    ``CONTACT_WORK + 7 * (number of shapes)`` floats of scratch."""
    ns, npairs, mode = int(data[off]), int(data[off + 1]), int(data[off + 2])
    S = off + HEADER
    t = work[0:CONTACT_WORK]
    if mode == PAIRS:
        P = S + SREC * ns
        for k in range(npairs):
            pair(S + SREC * int(data[P + 2 * k]), S + SREC * int(data[P + 2 * k + 1]), off,
                 data, R, r, w, v, com, F, N, acc, want, False, t)
    elif mode == ALL:
        for i in range(ns):
            for j in range(i + 1, ns):
                if data[S + SREC * i + 1] != data[S + SREC * j + 1]:
                    pair(S + SREC * i, S + SREC * j, off, data, R, r, w, v, com, F, N, acc,
                         want, False, t)
    else:
        _sweep(ns, off, data, R, r, w, v, com, F, N, acc, want, t,
               work[CONTACT_WORK:CONTACT_WORK + 7 * ns])


@internal(**UNCOUNTED)
def _sweep(ns, off, data, R, r, w, v, com, F, N, acc, want, t, b):
    """Sweep and prune: the shapes' bounding intervals along the axis over which their
    centres spread most, sorted; a pair is tested when its intervals and its bounding
    spheres overlap.  Planes (unbounded) are tested against every other shape."""
    S = off + HEADER
    cen, lo, hi, idx, perm = b[0:3 * ns], b[3 * ns:4 * ns], b[4 * ns:5 * ns], \
        b[5 * ns:6 * ns], b[6 * ns:7 * ns]
    m = 0
    for i in range(ns):
        s = S + SREC * i
        if data[s] == PLANE:
            continue
        pose(data, s, R, r, cen[3 * m:3 * m + 3], t[0:9])
        idx[m] = i
        m += 1
    axis, spread = 0, -1.0
    for a in range(3):
        mean, sq = 0.0, 0.0
        for k in range(m):
            mean += cen[3 * k + a]
            sq += cen[3 * k + a] ** 2
        var = sq - mean * mean / max(m, 1)
        if var > spread:
            axis, spread = a, var
    for k in range(m):
        bound = data[S + SREC * int(idx[k]) + 14]
        lo[k] = cen[3 * k + axis] - bound
        hi[k] = cen[3 * k + axis] + bound
    _sort(perm, lo, m)
    for a in range(m):
        i = int(perm[a])
        si = S + SREC * int(idx[i])
        for bb in range(a + 1, m):
            j = int(perm[bb])
            if lo[j] > hi[i]:
                break
            sj = S + SREC * int(idx[j])
            reach = data[si + 14] + data[sj + 14]
            d2 = (cen[3 * i] - cen[3 * j]) ** 2 + (cen[3 * i + 1] - cen[3 * j + 1]) ** 2 \
                + (cen[3 * i + 2] - cen[3 * j + 2]) ** 2
            if d2 <= reach * reach and data[si + 1] != data[sj + 1]:
                pair(si, sj, off, data, R, r, w, v, com, F, N, acc, want, False, t)
    for i in range(ns):
        si = S + SREC * i
        if data[si] != PLANE:
            continue
        for j in range(ns):
            sj = S + SREC * j
            if j != i and data[si + 1] != data[sj + 1] and (data[sj] != PLANE):
                pair(si, sj, off, data, R, r, w, v, com, F, N, acc, want, False, t)


@internal(**UNCOUNTED)
def _sort(perm, key, m):
    """``perm[0:m]`` the order of ``key[0:m]``, ascending (heapsort: no allocation)."""
    for a in range(m):
        perm[a] = a
    for start in range(m // 2 - 1, -1, -1):
        _sift(perm, key, start, m)
    for end in range(m - 1, 0, -1):
        perm[0], perm[end] = perm[end], perm[0]
        _sift(perm, key, 0, end)


@internal(**UNCOUNTED)
def _sift(perm, key, root, end):
    while True:
        child = 2 * root + 1
        if child >= end:
            return
        if child + 1 < end and key[int(perm[child + 1])] > key[int(perm[child])]:
            child += 1
        if key[int(perm[root])] < key[int(perm[child])]:
            perm[root], perm[child] = perm[child], perm[root]
            root = child
        else:
            return


@njit(**UNCOUNTED)
def gap(off, data, R, r, w, v, com, F, N, first, second, work):
    """The smallest signed distance (negative: penetration) of the element's pairs, or of
    the pair of its shapes ``first``, ``second`` (indices; ``first < 0``: all).  Every
    pair of a group is measured (no broad phase); ``FAR`` when none can touch."""
    ns, npairs, mode = int(data[off]), int(data[off + 1]), int(data[off + 2])
    S = off + HEADER
    acc = work[0:0]
    t = work[0:CONTACT_WORK]
    if first >= 0:
        return pair(S + SREC * first, S + SREC * second, off, data, R, r, w, v, com, F, N,
                    acc, False, True, t)
    best = FAR
    if mode == PAIRS:
        P = S + SREC * ns
        for k in range(npairs):
            best = min(best, pair(S + SREC * int(data[P + 2 * k]),
                                  S + SREC * int(data[P + 2 * k + 1]), off, data, R, r, w, v,
                                  com, F, N, acc, False, True, t))
        return best
    for i in range(ns):
        for j in range(i + 1, ns):
            if data[S + SREC * i + 1] != data[S + SREC * j + 1]:
                best = min(best, pair(S + SREC * i, S + SREC * j, off, data, R, r, w, v, com,
                                      F, N, acc, False, True, t))
    return best
