"""The hottest methods as one C call each (``kernels.fastcall``): built where a C
compiler is, the same numbers as the checked route to the last bit, and every argument it
does not take (or a kernel that fails) handed back to the checked route, which answers or
says what is wrong as before."""
import os
import shutil
import sysconfig

import numpy as np
import pytest

from mbdyn.algorithms import c_entries, recycling
from mbdyn.errors import ModelError, NonFiniteError
from mbdyn.kernels import fastcall
from test_merging import compiled_pair, robot, state


def _compiler():
    cc = (sysconfig.get_config_var("CC") or "cc").split()[0]
    return shutil.which(cc)


def test_the_extension_is_built_where_a_c_compiler_is():
    if _compiler() is None:
        pytest.skip("no C compiler here: mbdyn installs without its extension")
    assert fastcall.Entry is not None, "setup.py did not build mbdyn.kernels._fastcall"


needs_entry = pytest.mark.skipif(fastcall.Entry is None, reason="extension not built")


def made(model):
    """Make the model's pending C entries now (``c_entries.Pending.make``)."""
    for name in ("_c_mass_matrix", "_c_efforts"):
        if isinstance(getattr(model, name), c_entries.Pending):
            getattr(model, name).make()
    for entry in list(model._c_forward.values()):
        if isinstance(entry, c_entries.Pending):
            entry.make()
    return model


def _frozen(model, q, u, ud):
    """``model`` after its checked calls and with its C entries made."""
    for _ in range(2):
        model.mass_matrix(q), model.effort_array(q, u, ud)
        model.forward_dynamics(q, u, method="articulated")
    return made(model)


@needs_entry
def test_the_entries_are_made_once_a_method_is_called_often():
    """The first ``WARM`` calls after the checked one take the Python fast path (a model
    asked for its mass matrix a few times compiles no C function); the next makes the
    entry, and the results are the same throughout."""
    model = robot(loads=True).compile()
    q, u, ud = state(model)
    M = model.mass_matrix(q)
    tau = model.effort_array(q, u, ud)
    rates = model.forward_dynamics(q, u)             # "auto": articulated bodies from 6
    for _ in range(c_entries.WARM):
        assert np.array_equal(model.mass_matrix(q), M)
        assert np.array_equal(model.effort_array(q, u, ud), tau)
        assert np.array_equal(model.forward_dynamics(q, u), rates)
    assert isinstance(model._c_mass_matrix, c_entries.Pending)
    assert isinstance(model._c_forward["auto"], c_entries.Pending)
    assert np.array_equal(model.mass_matrix(q), M)
    assert np.array_equal(model.effort_array(q, u, ud), tau)
    assert np.array_equal(model.forward_dynamics(q, u), rates)
    assert isinstance(model._c_mass_matrix, fastcall.Entry)
    assert isinstance(model._c_efforts, fastcall.Entry)
    assert isinstance(model._c_forward["auto"], fastcall.Entry)


def _checked(model, q, u, ud):
    """The three results by the route with no fast call: lists converted and checked."""
    return (model.mass_matrix(list(q)), model.effort_array(list(q), list(u), list(ud)),
            model.forward_dynamics(list(q), list(u), method="articulated"))


@needs_entry
@pytest.mark.parametrize("case", [{}, {"loads": True}, {"loads": True, "actuator": True}])
def test_the_c_entries_give_the_checked_routes_numbers_bit_for_bit(case, monkeypatch):
    """On the merged tree and the full one, with force elements (the force function's
    address) and without, at three states each."""
    for model in compiled_pair(robot(**case), monkeypatch):
        _frozen(model, *state(model))
        assert model._c_mass_matrix is not None and model._c_efforts is not None
        forward = model._c_forward["articulated"]
        for seed in (1, 2, 3):
            q, u, ud = state(model, seed)
            M, tau = model._c_mass_matrix(q), model._c_efforts(q, u, ud)
            rates = forward(q, u)
            M_checked, tau_checked, rates_checked = _checked(model, q, u, ud)
            assert M.shape == (model.nu, model.nu) and tau.shape == (model.nu,)
            assert np.array_equal(M, M_checked) and np.array_equal(tau, tau_checked)
            assert np.array_equal(rates, rates_checked)
            assert np.array_equal(model.mass_matrix(q), M_checked)
            assert np.array_equal(model.effort_array(q, u, ud), tau_checked)
            assert np.array_equal(model.forward_dynamics(q, u, method="articulated"),
                                  rates_checked)
            # M u' = Q + f: the three agree with each other (an independent check)
            zero = np.zeros(model.nu)
            f = -model.effort_array(q, u, zero)
            assert np.allclose(M @ rates, f, rtol=1e-9, atol=1e-9 * np.abs(f).max())


class _Sub(np.ndarray):
    pass


def _others(x):
    """Arguments of the right numbers that the C entry does not take as they are."""
    n = x.shape[0]
    wide = np.zeros(2 * n)
    wide[::2] = x
    swapped = x.astype(x.dtype.newbyteorder())
    raw = np.zeros(8 * n + 1, np.uint8)
    unaligned = raw[1:].view(np.float64)
    unaligned[:] = x
    return {"list": list(x), "tuple": tuple(x), "float32": x.astype(np.float32),
            "int64": np.round(x).astype(np.int64), "strided": wide[::2],
            "reversed": x[::-1].copy()[::-1], "byte-swapped": swapped,
            "unaligned": unaligned, "subclass": x.view(_Sub), "2-d": x.reshape(1, n)}


@needs_entry
def test_what_the_c_entry_does_not_take_goes_to_the_checked_route():
    model = robot(loads=True).compile()
    q, u, ud = state(model)
    _frozen(model, q, u, ud)
    M_checked, tau_checked, rates_checked = _checked(model, q, u, ud)
    forward = model._c_forward["articulated"]
    for name, other in _others(q).items():
        assert model._c_mass_matrix(other) is None, name
        assert model._c_efforts(other, u, ud) is None, name
        assert model._c_efforts(q, u, _others(ud)[name]) is None, name
        assert forward(other, u) is None and forward(q, _others(u)[name]) is None, name
        if name in ("int64", "float32", "2-d"):
            continue                     # other numbers, or refused by the checked route
        assert np.allclose(model.mass_matrix(other), M_checked, rtol=1e-14, atol=0), name
        assert np.allclose(model.effort_array(q, u, _others(ud)[name]), tau_checked,
                           rtol=1e-14, atol=1e-14), name
        assert np.allclose(model.forward_dynamics(q, _others(u)[name], method="articulated"),
                           rates_checked, rtol=1e-14, atol=1e-14), name
    short = q[:-1].copy()
    assert model._c_mass_matrix(short) is None
    with pytest.raises(ModelError):
        model.mass_matrix(short)
    assert model._c_mass_matrix(q, q) is None and model._c_efforts(q, u) is None
    assert forward(q) is None and forward(q, u, u) is None and forward(q, u=u) is None
    read_only = q.copy()
    read_only.flags.writeable = False    # only read: taken
    assert np.array_equal(model._c_mass_matrix(read_only), M_checked)


@needs_entry
def test_a_kernel_that_fails_hands_over_to_the_checked_route_silently(capfd):
    """A quaternion of no length divides by zero in the kernel: the C function catches it
    (a ``cfunc`` would print it as unraisable), the entry returns None, and the method
    raises the checked route's error.  A NaN in the state likewise."""
    system = robot(loads=True)
    model = system.compile()
    q, u, ud = state(model)
    _frozen(model, q, u, ud)
    j4 = [k for k, name in enumerate(model.coordinates) if name.startswith("j4")]
    assert len(j4) == 4
    zero = q.copy()
    zero[j4] = 0.0
    nan = q.copy()
    nan[0] = np.nan
    for bad in (zero, nan):
        assert model._c_mass_matrix(bad) is None and model._c_efforts(bad, u, ud) is None
        assert model._c_forward["articulated"](bad, u) is None
        with pytest.raises(NonFiniteError):
            model.mass_matrix(bad)
        with pytest.raises(NonFiniteError):
            model.effort_array(bad, u, ud)
        with pytest.raises(NonFiniteError):
            model.forward_dynamics(bad, u, method="articulated")
    assert "Exception ignored" not in capfd.readouterr().err
    assert np.array_equal(model.mass_matrix(q), _checked(model, q, u, ud)[0])


@needs_entry
def test_the_entry_refuses_buffers_it_cannot_call_with():
    fb, ib = np.zeros(4), np.zeros(4, np.int64)
    address = fastcall.kernel("mass matrix").address
    fastcall.Entry(address, 0, fb, ib, 0, 1, 1, True)
    for args in [(0, 0, fb, ib, 0, 1, 1, True), (address, 3, fb, ib, 0, 1, 1, True),
                 (address, 0, ib, ib, 0, 1, 1, True), (address, 0, fb, fb, 0, 1, 1, True),
                 (address, 0, fb[::2], ib, 0, 1, 1, True),
                 (address, 0, fb, ib, 0, -1, 1, True)]:
        with pytest.raises(ValueError):
            fastcall.Entry(*args)
    with pytest.raises(TypeError):
        fastcall.Entry(address, 0, list(fb), ib, 0, 1, 1, True)


@needs_entry
def test_switched_off_by_the_environment(monkeypatch):
    monkeypatch.setenv("MBDYN_FASTCALL", "0")
    assert not fastcall.enabled()
    model = robot().compile()
    q, u, ud = state(model)
    _frozen(model, q, u, ud)
    assert model._c_mass_matrix is None and model._c_efforts is None
    assert model._c_forward["articulated"] is None
    assert model._fast_mass_matrix is not None   # the Python fast path instead
    assert os.environ["MBDYN_FASTCALL"] == "0"


def test_a_model_let_go_of_is_freed_at_once_while_its_entries_are_pending():
    """The pending entries hold their model weakly: no reference cycle keeps it until the
    cyclic collector runs (its buffers may be large)."""
    import gc
    import weakref
    model = robot(loads=True).compile()
    q, u, ud = state(model)
    for _ in range(3):
        model.mass_matrix(q), model.effort_array(q, u, ud), model.forward_dynamics(q, u)
    ref = weakref.ref(model)
    gc.disable()
    try:
        del model
        assert ref() is None
    finally:
        gc.enable()


@needs_entry
def test_a_spare_whose_release_calls_the_entry_again_leaves_it_consistent():
    """Releasing a spare may run Python code (a weak reference's callback) that calls the
    same entry: the entry's spares are settled before the release."""
    import sys
    import weakref
    model = made(_frozen(robot().compile(), *state(robot().compile())))
    q = state(model)[0]
    M_checked = _checked(model, q, *state(model)[1:])[0]
    inner = []
    a = model.mass_matrix(q)
    b = model.mass_matrix(q)
    a.shape = (a.size,)                  # no longer a spare's shape: never taken back
    watch = weakref.ref(a, lambda _: inner.append(model.mass_matrix(q)))
    del a                                # only the entry holds it now
    c = model.mass_matrix(q)             # makes a new one, releasing `a`: the callback
    assert watch() is None and len(inner) == 1
    assert len({id(b), id(c), id(inner[0])}) == 3
    # the counts: the name (or list) and the argument, and the entry's for its two spares
    # (c and the inner call's result; b was moved out)
    spare = 1 if recycling.FREE != -1 else 0
    counts = (sys.getrefcount(b), sys.getrefcount(c), sys.getrefcount(inner[0]))
    assert counts == (2, 2 + spare, 2 + spare)       # (taken outside the assert's rewrite)
    q2 = state(model, seed=2)[0]
    for _ in range(4):
        model.mass_matrix(q2)            # let go of at once: recycled, never one held
    for result in (b, c, inner[0]):
        assert np.array_equal(result, M_checked)


def test_an_entry_that_cannot_be_made_leaves_the_python_route(monkeypatch):
    """A C function that fails to compile, or sizes that do not match the buffers: a
    warning, and the methods answer by their Python route from then on."""
    model = robot(loads=True).compile()
    q, u, ud = state(model)
    M = model.mass_matrix(q)
    if model._c_mass_matrix is None:
        pytest.skip("the extension is not built or switched off")

    def broken(*args):
        raise RuntimeError("no compiler today")
    monkeypatch.setattr(fastcall, "entry", broken)
    for _ in range(c_entries.WARM):
        model.mass_matrix(q)
    with pytest.warns(RuntimeWarning, match="mass matrix could not be made"):
        assert np.array_equal(model.mass_matrix(q), M)
    assert model._c_mass_matrix is c_entries.off
    assert np.array_equal(model.mass_matrix(list(q)), M)     # a checked call keeps it off
    assert model._c_mass_matrix is c_entries.off


@needs_entry
def test_the_sizes_must_match_the_buffers():
    model = robot().compile()
    fb, ib = model._dynamics[:2]
    fastcall.entry("mass matrix", fb, ib, 0, model.nq, model.nu, True)
    for nq, nu in [(model.nq + 1, model.nu), (model.nq, model.nu - 1)]:
        with pytest.raises(ValueError, match="do not match"):
            fastcall.entry("mass matrix", fb, ib, 0, nq, nu, True)
