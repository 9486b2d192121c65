"""Kernels compiled without an entry from Python (``mbdyn.kernels.internal``): a call from
Python is refused with a clear error, never run (numba would jump to a null entry), and no
Python code of the package, its tests or benchmarks calls one."""
import ast
import os
import subprocess
import sys
import textwrap

import pytest
from numba.core import config

from mbdyn.kernels import internal as ki

#: with NUMBA_DISABLE_JIT=1 the kernels are plain Python functions: nothing to refuse
compiled_only = pytest.mark.skipif(config.DISABLE_JIT,
                                   reason="NUMBA_DISABLE_JIT=1: no compiled kernels")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KERNELS = os.path.join(ROOT, "mbdyn", "kernels")


def _decorated(node, names):
    for d in node.decorator_list:
        f = d.func if isinstance(d, ast.Call) else d
        if getattr(f, "id", None) in names or getattr(f, "attr", None) in names:
            return True
    return False


def _internal_kernels():
    """``{(module, function)}`` of every function decorated ``@internal(...)``."""
    found = set()
    for name in os.listdir(KERNELS):
        if name.endswith(".py"):
            tree = ast.parse(open(os.path.join(KERNELS, name)).read())
            found |= {(name[:-3], n.name) for n in tree.body
                      if isinstance(n, ast.FunctionDef) and _decorated(n, {"internal"})}
    return found


def _python_references(path, in_kernels):
    """``{(kernel module, name)}`` referenced by the Python-level code of ``path`` (the
    bodies of compiled functions skipped): ``module.name`` through an import of a kernel
    module, or a name imported from one (in a kernel module: its own functions too)."""
    tree = ast.parse(open(path).read())
    own = os.path.basename(path)[:-3] if in_kernels else None
    modules, names = {}, {}
    for n in ast.walk(tree):
        if isinstance(n, ast.ImportFrom):
            parts = (n.module or "").split(".")
            inside = in_kernels and n.level == 1
            if (inside and n.module is None) or parts[-1] == "kernels":
                modules.update({a.asname or a.name: a.name for a in n.names})
            elif inside or "kernels" in parts[:-1]:
                names.update({a.asname or a.name: (parts[-1], a.name) for a in n.names})
        elif isinstance(n, ast.Import):
            for a in n.names:
                if ".kernels." in f"{a.name}.":
                    modules[a.asname or a.name.split(".")[-1]] = a.name.split(".")[-1]
    found = set()

    def visit(node, compiled):
        if isinstance(node, ast.FunctionDef):
            compiled = compiled or _decorated(node, {"njit", "internal", "overload"})
        elif not compiled:
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in modules):
                found.add((modules[node.value.id], node.attr))
            elif isinstance(node, ast.Name):
                if node.id in names:
                    found.add(names[node.id])
                elif own is not None:
                    found.add((own, node.id))
        for child in ast.iter_child_nodes(node):
            visit(child, compiled)
    visit(tree, False)
    return found


def test_no_python_code_calls_an_internal_kernel():
    internal = _internal_kernels()
    assert len(internal) > 50                # the scan finds them (a wrong scan finds none)
    offenders = []
    for folder in ("mbdyn", "tests", "benchmarks"):
        for dirpath, _, files in os.walk(os.path.join(ROOT, folder)):
            for name in files:
                if name.endswith(".py"):
                    path = os.path.join(dirpath, name)
                    hits = _python_references(path, dirpath == KERNELS) & internal
                    offenders += [f"{os.path.relpath(path, ROOT)}: {m}.{f}" for m, f in hits]
    assert offenders == [], ("Python code calls internal kernels (give them @njit, or call "
                             f"them from compiled code): {offenders}")


def test_the_scan_sees_a_python_call(tmp_path):
    """The scan above would report a Python caller (a module that calls one)."""
    path = tmp_path / "caller.py"
    path.write_text("from mbdyn.kernels import joints as kj\n"
                    "from mbdyn.kernels.kinematics import walk\n"
                    "def f(q):\n    kj.rotation_about_axis(q, 0.1, q)\n    return walk\n")
    assert {("joints", "rotation_about_axis"), ("kinematics", "walk")} <= _python_references(
        str(path), False)


@compiled_only
def test_a_python_call_is_refused_with_the_kernel_named():
    """In a child process (a call that ran would crash it): the kernel is compiled (or
    loaded from the cache) as a compiled caller's callee first, then called from Python."""
    code = textwrap.dedent("""
        import numpy as np
        from numba import njit
        from mbdyn.kernels import joints

        @njit
        def caller(axis, angle, out):
            joints.rotation_about_axis(axis, angle, out)
            return out[0, 1]
        print("caller:", round(caller(np.array([0.0, 0.0, 1.0]), 0.3, np.empty((3, 3))), 12))
        assert joints.rotation_about_axis.overloads             # compiled, as a callee
        try:
            joints.rotation_about_axis(np.array([0.0, 0.0, 1.0]), 0.3, np.empty((3, 3)))
        except TypeError as exc:
            print("refused:", exc)
        R = np.empty((3, 3))
        joints.rotation_about_axis.py_func(np.array([0.0, 0.0, 1.0]), 0.3, R)
        print("py_func:", round(R[0, 1], 12))
    """)
    env = dict(os.environ, MBDYN_COMPILE_NOTICE="0")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "caller: -0.295520206661" in done.stdout
    assert ("refused: mbdyn.kernels.joints.rotation_about_axis is an internal kernel"
            in done.stdout)
    assert "py_func: -0.295520206661" in done.stdout       # -sin(0.3)


@compiled_only
def test_the_decorator_compiles_without_either_wrapper():
    options = {}

    class Probe(ki.InternalDispatcher):
        def __init__(self, py_func, locals, targetoptions):
            options.update(targetoptions)
            super().__init__(py_func=py_func, locals=locals, targetoptions=targetoptions)

    original, ki.InternalDispatcher = ki.InternalDispatcher, Probe
    try:
        ki.internal(_nrt=False)(lambda x: x)
    finally:
        ki.InternalDispatcher = original
    assert options["no_cpython_wrapper"] and options["no_cfunc_wrapper"]
    assert options["_nrt"] is False


@compiled_only
@pytest.mark.parametrize("constants", [False, True])
def test_constant_arguments_compile_once_unless_asked(constants):
    """A compiled caller's constants (``-1``, ``2``, ``True``) are typed as literal values:
    numba would compile the callee once per value (four copies of the closed loop's
    constraint rows).  An internal kernel compiles once per argument types, unless it
    asks for its constants (``motion``'s ``rates``)."""
    from numba import njit

    @ki.internal(constants=constants)
    def scaled(x, k, flag):
        return x * k if flag else x

    @njit
    def first(x):
        return scaled(x, -1, True)

    @njit
    def second(x):
        return scaled(x, 2, False)

    assert first(3.0) == -3.0 and second(3.0) == 3.0
    assert len(scaled.overloads) == (2 if constants else 1)
