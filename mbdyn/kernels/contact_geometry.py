"""The narrow phase of contact between shapes: for a pair of shapes in the world, the
contact point ``p``, the normal ``n`` (unit, from the first shape towards the second) and
the signed distance (negative: the shapes overlap by ``-distance``).  Pure geometry: the
force law and the broad phase are ``kernels.contact``'s.

A shape's world pose is its centre ``c`` and its axes ``A`` (flat 3x3, row-major:
``A[3 i + j]`` is the world component ``i`` of local axis ``j``).  Points of contact lie
amid the two surfaces, on the line of the normal through the deepest points: along that
line the force's moment is the same wherever it acts, so the elastic force is the
gradient of the stored energy ``k delta^(n+1) / (n+1)`` and the energy balance holds.
"""
import math


from .views import UNCOUNTED
from .internal import internal

#: a distance no contact reaches (a pair that cannot touch)
FAR = 1e300


@internal(**UNCOUNTED)
def pose(data, s, R, r, c, A):
    """World centre ``c`` and axes ``A`` of the shape record at ``data[s]`` (see
    ``kernels.contact``: frame at ``s + 1``, position at ``s + 2``, ``C`` at ``s + 5``)."""
    i = int(data[s + 1])
    if i < 0:
        for a in range(3):
            c[a] = data[s + 2 + a]
        for a in range(9):
            A[a] = data[s + 5 + a]
        return
    for a in range(3):
        c[a] = r[i, a] + R[i, a, 0] * data[s + 2] + R[i, a, 1] * data[s + 3] \
            + R[i, a, 2] * data[s + 4]
        for b in range(3):
            A[3 * a + b] = R[i, a, 0] * data[s + 5 + b] + R[i, a, 1] * data[s + 8 + b] \
                + R[i, a, 2] * data[s + 11 + b]


@internal(**UNCOUNTED)
def axis(A, j, out):
    """Local axis ``j`` of the axes ``A`` into ``out``."""
    for a in range(3):
        out[a] = A[3 * a + j]


@internal(**UNCOUNTED)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@internal(**UNCOUNTED)
def spheres(c1, r1, c2, r2, p, n):
    """Two spheres (centres ``c1``, ``c2``): along the line of their centres."""
    L2 = 0.0
    for q in range(3):
        n[q] = c2[q] - c1[q]
        L2 += n[q] * n[q]
    L = math.sqrt(L2)
    if L < 1e-300:                      # concentric: any direction
        n[0], n[1], n[2], L = 0.0, 0.0, 1.0, 1.0
    dist = math.sqrt(L2) - r1 - r2
    for q in range(3):
        n[q] /= L
        p[q] = c1[q] + (r1 + 0.5 * dist) * n[q]
    return dist


@internal(**UNCOUNTED)
def plane_point(e, c, g, p):
    """A point ``e`` against the plane through ``c`` with outward normal ``g``: its signed
    distance, and ``p`` amid the point and the plane."""
    dist = (e[0] - c[0]) * g[0] + (e[1] - c[1]) * g[1] + (e[2] - c[2]) * g[2]
    for q in range(3):
        p[q] = e[q] - 0.5 * dist * g[q]
    return dist


@internal(**UNCOUNTED)
def corner(kind, k, c, A, size, g, e, tmp):
    """The ``k``-th point of a shape that can touch a plane of outward normal ``g``: a
    box's corner (``kind`` 3; ``size`` its half sizes), a capsule's end sphere's deepest
    point (4) or the deepest point of a cylinder's end rim (5; ``size``: radius, half
    length)."""
    if kind == 3:
        for a in range(3):
            e[a] = c[a]
            for b in range(3):
                sign = 1.0 if (k >> b) & 1 else -1.0
                e[a] += sign * size[b] * A[3 * a + b]
        return
    sign = 1.0 if k else -1.0
    for a in range(3):
        e[a] = c[a] + sign * size[1] * A[3 * a + 2]
    if kind == 4:
        for a in range(3):
            e[a] -= size[0] * g[a]
        return
    ga = g[0] * A[2] + g[1] * A[5] + g[2] * A[8]
    s2 = 0.0
    for a in range(3):
        tmp[a] = -g[a] + ga * A[3 * a + 2]      # -g across the axis
        s2 += tmp[a] * tmp[a]
    sc = size[0] / math.sqrt(s2 + 1e-24)        # (as the floor contact's disk rim)
    for a in range(3):
        e[a] += sc * tmp[a]


@internal(**UNCOUNTED)
def segment_point(c, A, half, x, out):
    """The point of the segment ``c +- half * (local z)`` closest to ``x``."""
    s = (x[0] - c[0]) * A[2] + (x[1] - c[1]) * A[5] + (x[2] - c[2]) * A[8]
    s = min(max(s, -half), half)
    for a in range(3):
        out[a] = c[a] + s * A[3 * a + 2]


@internal(**UNCOUNTED)
def segments(c1, A1, h1, c2, A2, h2, o1, o2, t):
    """The closest points ``o1``, ``o2`` of two segments ``c +- h (local z)`` (Ericson,
    *Real-Time Collision Detection*, 5.1.9)."""
    d1, d2, rr = t[0:3], t[3:6], t[6:9]
    for a in range(3):
        d1[a] = 2.0 * h1 * A1[3 * a + 2]
        d2[a] = 2.0 * h2 * A2[3 * a + 2]
        rr[a] = (c1[a] - h1 * A1[3 * a + 2]) - (c2[a] - h2 * A2[3 * a + 2])
    a_, e_, f_ = _dot(d1, d1), _dot(d2, d2), _dot(d2, rr)
    c_, b_ = _dot(d1, rr), _dot(d1, d2)
    denom = a_ * e_ - b_ * b_
    s = min(max((b_ * f_ - c_ * e_) / denom, 0.0), 1.0) if denom > 1e-14 * a_ * e_ else 0.0
    tt = (b_ * s + f_) / e_
    if tt < 0.0:
        tt, s = 0.0, min(max(-c_ / a_, 0.0), 1.0)
    elif tt > 1.0:
        tt, s = 1.0, min(max((b_ - c_) / a_, 0.0), 1.0)
    for a in range(3):
        o1[a] = c1[a] - h1 * A1[3 * a + 2] + s * d1[a]
        o2[a] = c2[a] - h2 * A2[3 * a + 2] + tt * d2[a]


@internal(**UNCOUNTED)
def sphere_box(c, rad, cb, A, h, p, n, t):
    """A sphere (centre ``c``) against a box (centre ``cb``, axes ``A``, half sizes
    ``h``): the box's point nearest the centre or, for a centre inside the box, its
    nearest face; ``n`` from the sphere into the box."""
    x, y = t[0:3], t[3:6]
    inside = True
    for b in range(3):
        x[b] = (c[0] - cb[0]) * A[b] + (c[1] - cb[1]) * A[3 + b] + (c[2] - cb[2]) * A[6 + b]
        y[b] = min(max(x[b], -h[b]), h[b])
        if y[b] != x[b]:
            inside = False
    if inside:
        face, depth = 0, h[0] - abs(x[0])
        for b in range(1, 3):
            if h[b] - abs(x[b]) < depth:
                face, depth = b, h[b] - abs(x[b])
        sign = 1.0 if x[face] >= 0.0 else -1.0
        y[face] = sign * h[face]
        dist = -depth - rad
        for a in range(3):
            n[a] = -sign * A[3 * a + face]
    else:
        L = math.sqrt((x[0] - y[0]) ** 2 + (x[1] - y[1]) ** 2 + (x[2] - y[2]) ** 2)
        dist = L - rad
        for a in range(3):
            n[a] = -(A[3 * a] * (x[0] - y[0]) + A[3 * a + 1] * (x[1] - y[1])
                     + A[3 * a + 2] * (x[2] - y[2])) / L
    for a in range(3):                           # amid the box's point and the sphere's
        p[a] = 0.5 * (cb[a] + A[3 * a] * y[0] + A[3 * a + 1] * y[1] + A[3 * a + 2] * y[2]
                      + c[a] + rad * n[a])
    return dist


# ---------------------------------------------------------------- cams
@internal(**UNCOUNTED)
def profile(data, cb, phi, out):
    """A cam's radius and its first and second derivatives at the angle ``phi`` (any
    turn) into ``out[0:3]``: the periodic cubic spline of the profile block at ``cb``
    (``[n, knots (n+1), (x_k, y_k) (2n), coefficients (4n)]``)."""
    n = int(data[cb])
    K = cb + 1
    C = K + 3 * n + 1
    turn = 2.0 * math.pi
    x = phi - data[K]
    x = data[K] + (x - turn * math.floor(x / turn))
    lo, hi = 0, n
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if data[K + mid] <= x:
            lo = mid
        else:
            hi = mid
    s = x - data[K + lo]
    c3, c2, c1, c0 = (data[C + 4 * lo], data[C + 4 * lo + 1], data[C + 4 * lo + 2],
                      data[C + 4 * lo + 3])
    out[0] = ((c3 * s + c2) * s + c1) * s + c0
    out[1] = (3.0 * c3 * s + 2.0 * c2) * s + c1
    out[2] = 6.0 * c3 * s + 2.0 * c2


@internal(**UNCOUNTED)
def _cam_slope(data, cb, roller, x, y, phi, t):
    """``(h', h'')`` at ``phi`` of what the cam's contact point maximises: the profile's
    support ``P . (x, y)`` (a flat follower) or ``P . (x, y) - |P|^2 / 2`` (a roller at
    ``(x, y)``: the closest point)."""
    profile(data, cb, phi, t)
    r0, r1, r2 = t[0], t[1], t[2]
    cs, sn = math.cos(phi), math.sin(phi)
    d1 = (r1 * cs - r0 * sn) * x + (r1 * sn + r0 * cs) * y
    d2 = (r2 * cs - 2.0 * r1 * sn - r0 * cs) * x + (r2 * sn + 2.0 * r1 * cs - r0 * sn) * y
    if roller:
        d1 -= r0 * r1
        d2 -= r1 * r1 + r0 * r2
    return d1, d2


@internal(**UNCOUNTED)
def _cam_extremum(data, cb, roller, x, y, t):
    """The angle of the cam's contact point (see ``_cam_slope``): the best knot, then a
    safeguarded Newton iteration between its neighbours."""
    n = int(data[cb])
    K = cb + 1
    XY = K + n + 1
    best, kb = -FAR, 0
    for k in range(n):
        px, py = data[XY + 2 * k], data[XY + 2 * k + 1]
        h = px * x + py * y
        if roller:
            h -= 0.5 * (px * px + py * py)
        if h > best:
            best, kb = h, k
    phi = data[K + kb]
    a = phi - (data[K + kb] - data[K + kb - 1] if kb > 0 else data[K + n] - data[K + n - 1])
    b = data[K + kb + 1]
    for _ in range(60):
        d1, d2 = _cam_slope(data, cb, roller, x, y, phi, t)
        if d1 > 0.0:
            a = phi
        else:
            b = phi
        new = phi - d1 / d2 if d2 < 0.0 else 0.5 * (a + b)
        if not (a < new < b):
            new = 0.5 * (a + b)
        if abs(new - phi) <= 1e-15 * (1.0 + abs(phi)):
            return new
        phi = new
    return phi


@internal(**UNCOUNTED)
def cam_flat(c1, g, o, A, data, cb, p, e, t):
    """A flat follower (the plane through ``c1`` with outward normal ``g``) against a cam
    (centre ``o``, axes ``A``, profile block at ``cb``): the profile's point deepest
    through the plane, and its signed distance; ``FAR`` for a plane across the axis."""
    x = -(g[0] * A[0] + g[1] * A[3] + g[2] * A[6])
    y = -(g[0] * A[1] + g[1] * A[4] + g[2] * A[7])
    L = math.sqrt(x * x + y * y)
    if L < 1e-12:
        return FAR
    phi = _cam_extremum(data, cb, False, x / L, y / L, t)
    profile(data, cb, phi, t)
    cs, sn = t[0] * math.cos(phi), t[0] * math.sin(phi)
    for a in range(3):
        e[a] = o[a] + cs * A[3 * a] + sn * A[3 * a + 1]
    return plane_point(e, c1, g, p)


@internal(**UNCOUNTED)
def cam_roller(c1, rad, o, A, data, cb, p, n, t):
    """A roller (a circle of radius ``rad`` centred at ``c1``, in the cam's plane) against
    a cam: the profile's point closest to the centre; ``n`` from the roller to the cam."""
    x, y, z = 0.0, 0.0, 0.0
    for a in range(3):
        x += (c1[a] - o[a]) * A[3 * a]
        y += (c1[a] - o[a]) * A[3 * a + 1]
        z += (c1[a] - o[a]) * A[3 * a + 2]
    phi = _cam_extremum(data, cb, True, x, y, t)
    profile(data, cb, phi, t)
    cs, sn = math.cos(phi), math.sin(phi)
    px, py = t[0] * cs, t[0] * sn
    nx, ny = t[1] * sn + t[0] * cs, -(t[1] * cs - t[0] * sn)    # the tangent turned -90 deg
    L = math.sqrt(nx * nx + ny * ny)
    nx, ny = nx / L, ny / L                                     # outward normal
    dist = (x - px) * nx + (y - py) * ny - rad
    mx, my = 0.5 * (px + x - rad * nx), 0.5 * (py + y - rad * ny)
    for a in range(3):
        n[a] = -(nx * A[3 * a] + ny * A[3 * a + 1])
        p[a] = o[a] + mx * A[3 * a] + my * A[3 * a + 1] + z * A[3 * a + 2]
    return dist
