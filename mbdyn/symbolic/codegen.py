"""Code generation: derived equations -> Python source -> a numba-compiled right-hand side.

``compiled_rhs(model)`` returns a ``CompiledRHS``: calling it with ``(t, y)``, ``y = [q, u]``,
returns a NEW array ``[q', u']`` every call (scipy's ``solve_ivp`` keeps the arrays it is
given; a reused output buffer would silently corrupt its error estimates and dense output).

How it is made:

1. ``derive(model, "jourdain")`` (own frames, compact expressions) gives ``M(q, t)`` and
   ``f(q, u, t)``; the kinematic equations give ``q' = N(q) u`` (quaternion rates).
2. ``sympy.cse`` over the upper triangle of ``M``, ``f`` and ``q'`` -> straight-line Python
   with ``math`` functions; parameters are read from an array argument, so one compiled
   function serves every value of the model's parameters.
3. ``M u' = f`` is solved in the same function by a Cholesky factorisation (unrolled into
   scalars up to ``UNROLL_MAX`` speeds, loops beyond); a non-positive pivot returns NaN,
   which the Python wrapper turns into ``SingularMassMatrixError``.  Quaternions are
   normalised before use, like the numeric engine does.
4. The source is written to a cache directory (``$MBDYN_CACHE_DIR`` or
   ``~/.cache/mbdyn/symbolic``) under a hash of the model's structure and of this
   generator, and imported with ``@njit(cache=True)``: a model seen before -- in this
   process or an earlier one -- is neither re-derived nor recompiled.  In memory the
   compiled right-hand side is cached per ``Model`` object.
"""
from __future__ import annotations

import importlib.util
import os
import sys
import tempfile
import weakref
from pathlib import Path

import numpy as np
import sympy
from sympy.printing.pycode import PythonCodePrinter

from ..errors import ModelError, NonFiniteError, SingularMassMatrixError

UNROLL_MAX = 12
from .signature import GENERATOR_VERSION, model_signature  # noqa: F401

_MEMORY = weakref.WeakKeyDictionary()


# ---------------------------------------------------------------------------- model hash
def cache_dir():
    """Where generated modules live: ``$MBDYN_CACHE_DIR`` or ``~/.cache/mbdyn/symbolic``
    (a temporary directory if neither is writable)."""
    for candidate in (os.environ.get("MBDYN_CACHE_DIR"),
                      os.path.join(os.path.expanduser("~"), ".cache", "mbdyn", "symbolic"),
                      os.path.join(tempfile.gettempdir(), "mbdyn-symbolic")):
        if not candidate:
            continue
        try:
            os.makedirs(candidate, exist_ok=True)
            if os.access(candidate, os.W_OK):
                return Path(candidate)
        except OSError:
            continue
    raise OSError("no writable cache directory for generated code; set MBDYN_CACHE_DIR")


# ---------------------------------------------------------------------------- source
class _Printer(PythonCodePrinter):
    def _print_Pow(self, expr, rational=False):
        b, e = expr.args
        if e.is_Integer and 2 <= e <= 4:
            base = self.parenthesize(b, 1000)       # always parenthesise non-atoms
            return "*".join([base] * int(e))
        if e == -1:
            return "1.0/" + self.parenthesize(b, 1000)
        return super()._print_Pow(expr, rational=rational)

    def _print_Rational(self, expr):
        return f"{float(expr.p)!r}/{float(expr.q)!r}"

    def _print_Integer(self, expr):
        return f"{float(expr)!r}"


def generate_source(derivation, function_name="rhs"):
    """Python source of ``rhs(t, y, p)`` for a derivation (see the module docstring)."""
    model = derivation.model
    sym = derivation.walk.sym
    nq, nu = model.nq, model.nu
    rename, params = _local_names(sym)
    exprs, slots, trivial_qdot = _expressions(derivation)
    exprs = [sympy.sympify(e).xreplace(rename) for e in exprs]
    bad = set().union(*[e.free_symbols for e in exprs]) - set(rename.values())
    if bad:
        raise ModelError(f"model {model.name!r}: the equations use {sorted(s.name for s in bad)}, "
                         "which are not parameters, coordinates, speeds or t")
    repl, reduced = sympy.cse(exprs, symbols=sympy.numbered_symbols("_x"), order="none")
    pr = _Printer({"fully_qualified_modules": True, "standard": "python3"})
    L = []
    w = L.append
    _header(w, model, params, repl, reduced)
    w("@njit(cache=True, error_model='numpy')")
    w(f"def {function_name}(t, y, p):")
    w('    """[q\', u\'] at (t, y = [q, u]) with parameters p; a new array every call."""')
    for k in range(nq):
        w(f"    _q{k} = y[{k}]")
    for k in range(nu):
        w(f"    _u{k} = y[{nq + k}]")
    for k in range(len(params)):
        w(f"    _p{k} = p[{k}]")
    for a in _quaternion_starts(model):
        w(f"    _n = math.sqrt(_q{a}*_q{a} + _q{a+1}*_q{a+1} + _q{a+2}*_q{a+2} + _q{a+3}*_q{a+3})")
        for k in range(a, a + 4):
            w(f"    _q{k} = _q{k} / _n")
    for s, v in repl:
        w(f"    {s.name} = {pr.doprint(v)}")
    for (kind, r, c), e in zip(slots, reduced):
        name = {"M": f"_M{r}_{c}", "f": f"_f{r}", "qd": f"_qd{r}"}[kind]
        w(f"    {name} = {pr.doprint(e)}")
    w(f"    out = np.empty({nq + nu})")
    for k in range(nq):
        w(f"    out[{k}] = " + (f"_u{trivial_qdot[k]}" if k in trivial_qdot else f"_qd{k}"))
    if nu <= UNROLL_MAX:
        _unrolled_cholesky(w, nu, nq)
    else:
        _looped_cholesky(w, nu, nq)
    w("    return out")
    w("")
    return "\n".join(L) + "\n"


def _local_names(sym):
    """Every model symbol renamed to a safe local name (``_q0``, ``_u0``, ``_p0``, ``t``);
    and the parameters' symbols in order."""
    rename = {}
    for k, s in enumerate(sym.q):
        rename[s] = sympy.Symbol(f"_q{k}", real=True)
    for k, s in enumerate(sym.u):
        rename[s] = sympy.Symbol(f"_u{k}", real=True)
    params = list(sym.params.values())
    for k, s in enumerate(params):
        rename[s] = sympy.Symbol(f"_p{k}", real=True)
    rename[sym.t] = sympy.Symbol("t", real=True)
    return rename, params


def _expressions(derivation):
    """The expressions the function computes: the upper triangle of ``M``, ``f``, and the
    coordinate rates that are not a speed itself; their slots; ``{q index: u index}`` of
    the rates that are."""
    sym, nu = derivation.walk.sym, derivation.model.nu
    M, f = derivation.mass_matrix, derivation.forcing
    qdot = [derivation.walk.qdot.get(s, sym.u[k] if k < nu else 0) for k, s in enumerate(sym.q)]
    exprs, slots = [], []
    for r in range(nu):
        for c in range(r, nu):
            exprs.append(M[r, c])
            slots.append(("M", r, c))
    for r in range(nu):
        exprs.append(f[r])
        slots.append(("f", r, None))
    trivial_qdot = {}
    for k, e in enumerate(qdot):
        if isinstance(e, sympy.Symbol) and e in sym.u:
            trivial_qdot[k] = sym.u.index(e)
        else:
            exprs.append(e)
            slots.append(("qd", k, None))
    return exprs, slots, trivial_qdot


def _header(w, model, params, repl, reduced):
    """The generated module's head: its origin, imports and the model's names."""
    w(f"# Generated by mbdyn.symbolic.codegen for model {model.name!r}: do not edit.")
    after = sum(sympy.count_ops(v) for _, v in repl) + sum(sympy.count_ops(e) for e in reduced)
    w(f"# M u' = f by Newton-Euler-Jourdain, cse'd to {after} operations.")
    w("import math")
    w("import numpy as np")
    w("from numba import njit")
    w("")
    w(f"NQ = {model.nq}")
    w(f"NU = {model.nu}")
    w(f"PARAMETERS = {tuple(p.name for p in params)!r}")
    w(f"COORDINATES = {tuple(model.coordinates)!r}")
    w(f"SPEEDS = {tuple(model.speeds)!r}")
    w("")
    w("")


def _quaternion_starts(model):
    """Index in ``q`` of the first component of every free joint's quaternion."""
    starts, k = [], 0
    for j in model.elements[1]:
        if j.drive is not None or not j.nq:
            continue
        if j.kind == "spherical":
            starts.append(k)
        elif j.kind == "free":
            starts.append(k + 3)
        k += j.nq
    return starts


def _unrolled_cholesky(w, n, nq):
    for j in range(n):
        s = f"_M{j}_{j}" + "".join(f" - _L{j}_{k}*_L{j}_{k}" for k in range(j))
        w(f"    _s = {s}")
        w("    if not _s > 0.0:")
        w("        out[:] = np.nan")
        w("        return out")
        w(f"    _L{j}_{j} = math.sqrt(_s)")
        for i in range(j + 1, n):
            s = f"_M{j}_{i}" + "".join(f" - _L{i}_{k}*_L{j}_{k}" for k in range(j))
            w(f"    _L{i}_{j} = ({s}) / _L{j}_{j}")
    for i in range(n):
        s = f"_f{i}" + "".join(f" - _L{i}_{k}*_z{k}" for k in range(i))
        w(f"    _z{i} = ({s}) / _L{i}_{i}")
    for i in range(n - 1, -1, -1):
        s = f"_z{i}" + "".join(f" - _L{k}_{i}*_a{k}" for k in range(i + 1, n))
        w(f"    _a{i} = ({s}) / _L{i}_{i}")
    for i in range(n):
        w(f"    out[{nq + i}] = _a{i}")


def _looped_cholesky(w, n, nq):
    w(f"    M = np.empty(({n}, {n}))")
    w(f"    x = np.empty({n})")
    for r in range(n):
        for c in range(r, n):
            w(f"    M[{r}, {c}] = _M{r}_{c}")
        w(f"    x[{r}] = _f{r}")
    w(f"    for j in range({n}):")
    w("        s = M[j, j]")
    w("        for k in range(j):")
    w("            s -= M[k, j] * M[k, j]")
    w("        if not s > 0.0:")
    w("            out[:] = np.nan")
    w("            return out")
    w("        M[j, j] = math.sqrt(s)")
    w(f"        for i in range(j + 1, {n}):")
    w("            s = M[j, i]")
    w("            for k in range(j):")
    w("                s -= M[k, i] * M[k, j]")
    w("            M[j, i] = s / M[j, j]")
    w(f"    for i in range({n}):")
    w("        s = x[i]")
    w("        for k in range(i):")
    w("            s -= M[k, i] * x[k]")
    w("        x[i] = s / M[i, i]")
    w(f"    for i in range({n} - 1, -1, -1):")
    w("        s = x[i]")
    w(f"        for k in range(i + 1, {n}):")
    w("            s -= M[i, k] * x[k]")
    w("        x[i] = s / M[i, i]")
    w(f"    for i in range({n}):")
    w(f"        out[{nq} + i] = x[i]")


# ---------------------------------------------------------------------------- loading
def _load_module(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


class CompiledRHS:
    """The generated right-hand side of a model.

    ``rhs(t, y)`` -> new array ``[q', u']``; ``accelerations(q, u, t)`` -> ``u'``;
    ``function`` is the raw numba function ``function(t, y, p)``, ``parameters`` the
    array ``p`` (the model's parameter values), ``source``/``path`` the generated code.
    """

    def __init__(self, model, module, path):
        self.model = model
        self.module = module
        self.path = Path(path)
        self.function = module.rhs
        self.parameters = np.array([float(model.parameters[n]) for n in module.PARAMETERS])
        self.nq, self.nu = module.NQ, module.NU

    @property
    def source(self):
        return self.path.read_text()

    def __call__(self, t, y):
        out = self.function(float(t), np.ascontiguousarray(y, dtype=float), self.parameters)
        if not np.isfinite(out).all():
            self._fail(float(t), np.asarray(y, dtype=float), out)
        return out

    def accelerations(self, q, u, t=0.0):
        return self(t, np.concatenate([np.asarray(q, dtype=float),
                                       np.asarray(u, dtype=float)]))[self.nq:]

    def _fail(self, t, y, out):
        model = self.model
        q, u = y[:self.nq], y[self.nq:]
        if not np.all(np.isfinite(y)):
            bad = [n for n, x in zip(model.coordinates + model.speeds, y) if not np.isfinite(x)]
            raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the state holds "
                                 f"non-finite values in {', '.join(bad)}")
        if np.all(np.isnan(out[self.nq:])):
            # the generated Cholesky met a non-positive pivot: let the engine explain it
            model.mass_matrix(q, t)
            model.forward_dynamics(q, u, t)
            raise SingularMassMatrixError(f"model {model.name!r}, t={t:.6g}: the mass matrix "
                                          "of the generated equations is not positive "
                                          "definite", ())
        bad = [n for n, x in zip(model.coordinates + model.speeds, out) if not np.isfinite(x)]
        raise NonFiniteError(f"model {model.name!r}, t={t:.6g}: the generated right-hand "
                             f"side came out non-finite for {', '.join(bad)}")


def compiled_rhs(model, *, rebuild=False):
    """The ``CompiledRHS`` of a compiled ``Model`` (or a ``System``), derived, generated and
    compiled on first use, then cached (see the module docstring)."""
    from .derive import _as_model, derive
    model = _as_model(model)
    if getattr(model, "flexible_bodies", ()):
        raise ModelError(f"model {model.name!r}: the generated right-hand side does not "
                         f"take flexible bodies ({', '.join(model.flexible_bodies)}); use a "
                         "numeric method (method='auto'); mb.derive (mbdyn eom) writes "
                         "their equations")
    if getattr(model, "loop_joints", ()):
        raise ModelError(f"model {model.name!r}: its loop joints ({', '.join(model.loop_joints)}) "
                         "close kinematic loops, and the generated right-hand side solves "
                         "M u' = f of the tree only; use a numeric method (method='auto'); "
                         "mb.derive writes the constraint equations and the equations with "
                         "multipliers")
    if not rebuild and model in _MEMORY:
        return _MEMORY[model]
    key = model_signature(model)
    name = f"mbdyn_eom_{key[:24]}"
    directory = cache_dir()
    path = directory / f"{name}.py"
    if rebuild or not path.exists():
        d = derive(model, "jourdain", measure=False)
        src = generate_source(d)
        tmp = directory / f".{name}.{os.getpid()}.tmp"
        tmp.write_text(src)
        os.replace(tmp, path)
    module = sys.modules.get(name) if not rebuild else None
    if module is None or getattr(module, "__file__", None) != str(path):
        module = _load_module(path, name)
    rhs = CompiledRHS(model, module, path)
    _MEMORY[model] = rhs
    return rhs
