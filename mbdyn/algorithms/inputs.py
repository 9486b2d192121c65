"""The state and the inputs an evaluation starts from, on a compiled model's workspace
(``Model``'s arrays): the free ``q, u`` scattered into joint space, the drives' values at
``t``, the loads and force laws given as Python functions; and the checks that name what
made a result non-finite (the state, a load, a drive, or the equations themselves).
"""
from __future__ import annotations


import numpy as np

from ..errors import ModelError, NonFiniteError, SingularMassMatrixError
from ..kernels import forces as kf
from ..kernels.entries import direct
from .c_entries import pending


def fill(model, q, u, t):
    """Scatter the free state and the drives into joint-space vectors; evaluate the
    loads that are functions of ``(t, q, u)``."""
    q, u = model._as_arrays(q, u)
    if q.shape != (model.nq,) or u.shape != (model.nu,):
        raise ModelError(f"model {model.name!r} expects q of length {model.nq} and u of "
                         f"length {model.nu}, got {q.shape} and {u.shape}")
    if model._time_inputs:
        model._qfull[model._free_q] = q
        model._ufull[model._free_u] = u
    else:                             # every joint is free: the layouts coincide
        model._qfull[:] = q
        model._ufull[:] = u
    model._udfull[:] = 0.0
    model._fill_inputs(q, u, t)
    return q, u


def as_arrays(model, q, u):
    try:
        return np.asarray(q, dtype=float), np.asarray(u, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"model {model.name!r}: q and u must be arrays of numbers "
                         f"(q: {model.nq} coordinates, u: {model.nu} speeds)") from None


def require_finite(model, q, u, t=0.0):
    """``NonFiniteError`` naming the coordinates and speeds that are NaN or Inf."""
    bad = [n for n, x in zip(model.coordinates + model.speeds,
                             np.concatenate([np.ravel(q), np.ravel(u)]))
           if not np.isfinite(x)]
    if bad:
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the state holds non-finite "
                             f"values in {', '.join(bad)}; give finite coordinates and "
                             "speeds")


def plain(x, n):
    """Whether ``x`` is what the packed kernels take as it is: a float64 numpy array of
    ``n`` entries, C-contiguous and writable (anything else is converted first)."""
    return (type(x) is np.ndarray and x.dtype == np.float64 and x.shape == (n,)
            and x.flags.c_contiguous and x.flags.writeable)


#: what ``fits`` compares against: the ndarray type, float64 (native byte order)
ND, F64 = np.ndarray, np.dtype(np.float64)
#: the fast calls' allocation, one name lookup instead of two
empty = np.empty


def fits(x):
    """Whether ``x`` is of the type the compiled entries were made for (``freeze``): a
    numpy array (not a subclass) of native float64, one-dimensional.  Their sizes and
    strides the kernels check themselves (``kernels.packed.contiguous``: the strides are
    a tuple made at each reading here, 30 ns an array).  Alignment is not asked (it costs
    as much as the rest): numba's code reads a float64 with no more than 8-byte alignment
    assumed, which x86-64 and AArch64 load from any address (tests/test_merging.py runs
    an unaligned array through).  The hottest methods write this test inline for their
    arguments: a call costs as much as the test."""
    return type(x) is ND and x.dtype is F64 and x.ndim == 1


def freeze(model, key, kernel, packed, args, *rest):
    """After a checked call of ``kernel`` on ``(*packed, *args)`` succeeded: enter
    ``(its compiled entry for these types, *packed, *rest)`` into the model's fast calls
    under ``key`` (``kernels.entries.direct``), when it can be had.  The ordinary per-call
    methods then call it first, with no dispatch, once their arguments pass ``fits``;
    the kernel checks their sizes."""
    call = direct(kernel, (*packed, *args))
    if call is not None:
        model._fast_calls[key] = (call, *packed, *rest)
        if key in FAST_ATTRIBUTES:           # the hottest: an attribute, not a dict lookup
            setattr(model, FAST_ATTRIBUTES[key], model._fast_calls[key])
    name = C_ATTRIBUTES.get(key)
    if name is not None and getattr(model, name) is None:
        # and one C call once called often (c_entries); kept through later checked calls
        setattr(model, name, pending(model, key, packed,
                                     lambda owner, entry: setattr(owner, name, entry)))


#: the fast calls also held as attributes of the model (``freeze``; None until then): a
#: dictionary lookup is 5 % of a mass matrix of twelve speeds
FAST_ATTRIBUTES = {"mass matrix": "_fast_mass_matrix", "efforts": "_fast_efforts"}
#: the same two as one C call each (``kernels.fastcall``; None without the extension)
C_ATTRIBUTES = {"mass matrix": "_c_mass_matrix", "efforts": "_c_efforts"}


def state(model, q, u):
    q, u = model._as_arrays(q, u)
    if q.shape != (model.nq,) or u.shape != (model.nu,):
        raise ModelError(f"model {model.name!r} expects q of length {model.nq} and u of "
                         f"length {model.nu}, got {q.shape} and {u.shape}")
    return q, u


def fill_inputs(model, q, u, t):
    """The drives' values and the loads given as Python functions, at ``t``."""
    for name, kq, ku, drive in model._time_inputs:
        model._qfull[kq] = drive.position(t)
        model._ufull[ku] = drive.velocity(t)
        model._udfull[ku] = drive.acceleration(t)
    if model._laws:
        model._fill_laws(q, u, t)
    for name, row, fn in model._load_functions:
        try:
            val = np.asarray(fn(t, q, u), dtype=float).reshape(-1)
        except (ModelError, NonFiniteError, SingularMassMatrixError):
            raise
        except Exception as exc:
            raise ModelError(f"load {name!r}: its function raised {type(exc).__name__}: "
                             f"{exc} (at t={t:.6g})") from exc
        if val.shape != (3,):
            raise ModelError(f"load {name!r}: its function returned {val.size} values at "
                             f"t={t}; it must return three")
        row[:] = val


def fill_laws(model, q, u, t):
    """Each force law's value at the state: ``law(x, x')`` of a spring-damper's
    elongation or a joint's coordinate offset, written where the kernel reads it."""
    model._qfull[model._free_q] = q
    model._ufull[model._free_u] = u
    kinematics_done = False
    fd = model._force_data
    for el, slot, law in model._laws:
        p = el.params
        if el.kind == "joint-spring-damper":
            j = model._joint[p["joint"]]
            i = model._frame_index[j.child]
            x = model._qfull[model._qoff[i]] - p["rest"]
            v = model._ufull[model._uoff[i]]
        else:
            if not kinematics_done:
                from ..kernels.kinematics import forward_kinematics
                forward_kinematics(*model._tree, model._qfull, model._ufull, model._udfull,
                                   *model._kin_out[:9])
                kinematics_done = True
            ends = []
            for frame, point in zip(el.frames, (p["point_a"], p["point_b"])):
                if frame == "ground":
                    ends.append((point, np.zeros(3)))
                else:
                    i = model._frame_index[frame]
                    lever = model._R[i] @ point
                    ends.append((model._r[i] + lever, model._v[i] + np.cross(model._w[i], lever)))
            d = ends[1][0] - ends[0][0]
            L = float(np.sqrt(d @ d))
            e = d / np.sqrt(L * L + p["min_length"] ** 2)
            x = L - p["free_length"]
            v = float(e @ (ends[1][1] - ends[0][1]))
        try:
            value = float(law(x, v))
        except Exception as exc:
            raise ModelError(f"force {el.name!r}: its law failed at x={x:.6g}, v={v:.6g} "
                             f"(t={t:.6g}): {type(exc).__name__}: {exc}") from None
        if not np.isfinite(value):
            raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the law of force "
                                 f"{el.name!r} gave {value} at x={x:.6g}, v={v:.6g}")
        fd[slot] = value


def check_finite(model, q, u, t, out, what, names=None):
    if np.all(np.isfinite(out)):
        return
    if not np.all(np.isfinite(q)) or not np.all(np.isfinite(u)):
        bad = [n for n, x in zip(model.coordinates + model.speeds, np.concatenate([q, u]))
               if not np.isfinite(x)]
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the state holds non-finite "
                             f"values in {', '.join(bad)}")
    for name, row, _ in model._load_functions:
        if not np.all(np.isfinite(row)):
            raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: load {name!r} returned "
                                 f"non-finite values {row.tolist()}")
    for name, kq, ku, _ in model._driven:
        if not (np.isfinite(model._qfull[kq]) and np.isfinite(model._ufull[ku])
                and np.isfinite(model._udfull[ku])):
            raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the drive of joint "
                                 f"{name!r} gave a non-finite value")
    blame = force_element_blame(model, q, u, t)
    if blame:
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: {what} came out non-finite; "
                             + blame)
    bad = [n for n, x in zip(names or model.speeds, out) if not np.isfinite(x)]
    raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: {what} came out non-finite "
                         f"for {', '.join(bad) or 'some entries'}")


def lambdify_load(model, name, exprs):
    """A callable ``(t, q, u) -> 3 values`` from sympy expressions of ``t`` and the
    coordinate and speed names."""
    import sympy
    names = ("t",) + model.coordinates + model.speeds
    used = {s.name for e in exprs for s in e.free_symbols}
    unknown = sorted(used - set(names))
    if unknown:
        raise ModelError(f"load {name!r}: its expression uses {', '.join(unknown)}, which "
                         "are neither t nor coordinates or speeds of the model "
                         f"({', '.join(names[1:])})")
    args = [sympy.Symbol(n) for n in names]
    renamed = [e.subs({s: sympy.Symbol(s.name) for s in e.free_symbols}) for e in exprs]
    fn = sympy.lambdify(args, sympy.Matrix(renamed).T, "numpy")

    def load(t, q, u):
        return np.asarray(fn(t, *q, *u), dtype=float).reshape(3)
    return load


def division_by_zero(model, q, t=0.0):
    """The error to raise when a kernel divided by zero at the coordinates ``q``: a
    quaternion of zero length (named, with what to give instead), else the division
    itself, with the time and the state's coordinates."""
    q = np.array(q, dtype=float).reshape(-1)
    if q.shape == (model.nq,):
        model.normalize_quaternions(q)          # raises, naming a zero quaternion
    return NonFiniteError(f"model {model.name!r}, t={t:.6g}: a division by zero in the "
                          "numeric kernels at this state; check the coordinates "
                          f"({', '.join(model.coordinates)}) and the model's data")


#: a force element's force or moment beyond this (newtons, newton metres) is named as the
#: likely cause of a non-finite result: squared, or times a step, it leaves the doubles
HUGE_FORCE = 1e150


def force_element_blame(model, q, u, t):
    """Which force element gives a non-finite or huge force at the state ``(q, u, t)``:
    each element evaluated alone (its wrench on zeroed loads); the message naming it and
    its force, or ``None``."""
    if not model.forces or not model._force_int.shape[0]:
        return None
    try:
        model._kinematics_kernel(np.asarray(q, float), np.asarray(u, float), t)
    except Exception:           # the state itself is unusable: said by the caller
        return None
    F, N = np.zeros_like(model._F), np.zeros_like(model._N)
    for k, el in enumerate(model._force_elements):
        F[:] = 0.0
        N[:] = 0.0
        kf.force_elements(model._force_int[k:k + 1], model._force_data, model._parent,
                          model._axis, model._com, model._qfull, model._ufull, model._R,
                          model._r, model._w, model._v, F, N, np.zeros(2), model._scratch,
                          model._force_shapes)
        size = max(np.abs(F).max(initial=0.0), np.abs(N).max(initial=0.0))
        if not np.isfinite(size) or size > HUGE_FORCE:
            return (f"force element {el.name!r} ({el.kind}) gives a force of {size:.3g} at "
                    "this state: check its stiffness, its tables (their slope beyond the "
                    "last point is held) and the units")
    return None
