"""The mass matrix and the generalized forces come back as new arrays, some of them
recycled (``algorithms.recycling``): a result the caller still reaches is never written, and
one it let go of is taken back."""
import gc
import subprocess
import sys
import textwrap
import warnings
import weakref

import numpy as np
import pytest

from mbdyn.algorithms import recycling
from mbdyn.kernels import fastcall
from test_fastcall import made
from test_merging import robot, state


@pytest.fixture(scope="module", params=["C", "Python"])
def frozen(request):
    with pytest.MonkeyPatch.context() as patch:
        if request.param == "Python":    # as where the extension is not built
            patch.setenv("MBDYN_FASTCALL", "0")
        yield _frozen(request)


def _frozen(request):
    """A model whose two hot methods have their direct calls (``inputs.freeze``), states,
    and the results at them, computed by the checked route (a list as input).  Twice:
    with the C entries (``kernels.fastcall``), which recycle in C, and without them, as
    where the extension is not built (the Python fast path recycles)."""
    model = robot(loads=True).compile()
    q, u, ud = state(model)
    q2, u2, ud2 = state(model, seed=2)
    for _ in range(2):
        model.mass_matrix(q), model.effort_array(q, u, ud)
        model.forward_dynamics(q, u, method="articulated")
    assert model._fast_mass_matrix is not None and model._fast_efforts is not None
    if request.param == "C":
        if not fastcall.enabled():
            pytest.skip("mbdyn.kernels._fastcall is not built here")
        made(model)
        assert isinstance(model._c_mass_matrix, fastcall.Entry)
        assert isinstance(model._c_efforts, fastcall.Entry)
    else:
        assert model._c_mass_matrix is None and model._c_efforts is None
    checked = {"M": model.mass_matrix(list(q)), "M2": model.mass_matrix(list(q2)),
               "tau": model.effort_array(list(q), u, ud),
               "tau2": model.effort_array(list(q2), u2, ud2),
               "fd": model.forward_dynamics(list(q), u, method="articulated"),
               "fd2": model.forward_dynamics(list(q2), u2, method="articulated")}
    return model, (q, u, ud), (q2, u2, ud2), checked


def calls(model, a, b):
    """The three methods at the states ``a`` and ``b``, by their direct calls."""
    def fd(x):
        return lambda: model.forward_dynamics(x[0], x[1], method="articulated")
    return ((lambda: model.mass_matrix(a[0]), lambda: model.mass_matrix(b[0]), "M", "M2"),
            (lambda: model.effort_array(*a), lambda: model.effort_array(*b), "tau", "tau2"),
            (fd(a), fd(b), "fd", "fd2"))


def test_a_result_the_caller_reaches_is_never_written(frozen):
    model, a, b, checked = frozen
    for first, other, key, key2 in calls(model, a, b):
        kept = first()
        row = first()[0]                 # a view: reaches its array through .base
        listed = [first() for _ in range(3)]
        view = np.asarray(first())
        for _ in range(5):
            other()                      # discarded: free to recycle
            held = other()
        assert np.array_equal(held, checked[key2])
        for result in (kept, view, *listed):
            assert np.array_equal(result, checked[key])
        assert np.array_equal(row, checked[key][0])
        assert len({id(r) for r in (kept, view, *listed, held)}) == 6


def test_each_call_in_a_loop_is_right(frozen):
    model, a, b, checked = frozen
    for first, other, key, key2 in calls(model, a, b):
        result = None
        for k in range(6):               # the name holds the last result during the call
            result = (first if k % 2 else other)()
            assert np.array_equal(result, checked[key if k % 2 else key2])


def test_a_result_let_go_of_is_taken_back(frozen):
    """Taken back where reference counts are exact; where they are not (``FREE`` -1)
    every call allocates, and a result let go of is never handed out again.  The forward
    dynamics recycles only in its C entry (its Python route copies the workspace)."""
    model, a, b, checked = frozen
    for first, other, key, _ in calls(model, a, b):
        result = first()
        ref = weakref.ref(result)        # does not hold it
        del result
        gc.collect()
        again = first()
        recycles = recycling.FREE != -1 and (
            key != "fd" or isinstance(model._c_forward["articulated"], fastcall.Entry))
        assert (again is ref()) == recycles
        assert np.array_equal(again, checked[key])


def test_the_count_of_a_free_spare_is_calibrated():
    """The count the hot paths compare against is the one a spare nothing else refers to
    has; one more reference (the caller's) makes it differ.  Recycling is off only where
    the counts are not exact or did not come out as expected."""
    if recycling.FREE == -1:
        assert (not recycling._exact_counts()
                or recycling._count_when_free() != recycling.EXPECTED)
        return
    spare = recycling.spares(2)
    result = spare[0]
    assert recycling.refcount(result) == recycling.FREE
    held = spare[0]
    assert recycling.refcount(result) == recycling.FREE + 1
    del held


def _alter(x, how):
    """``x`` made read-only, re-typed or re-strided in place (True), or False where this
    numpy refuses the change."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if how == "read-only":
                x.flags.writeable = False
            elif how == "dtype":
                x.dtype = np.int64
            else:                        # the same bytes, read with other strides
                x.strides = tuple(reversed(x.strides)) if x.ndim == 2 else (0,)
    except (AttributeError, ValueError, TypeError):
        return False
    return True


@pytest.mark.parametrize("how", ["read-only", "dtype", "strides"])
def test_a_result_altered_then_let_go_of_does_not_come_back_altered(frozen, how):
    """A caller may make its result read-only, or set its dtype or strides, before letting
    go of it: the next results are still writable float64 arrays of the right numbers."""
    model, a, b, checked = frozen
    for first, _, key, _ in calls(model, a, b):
        altered = 0
        for _ in range(3):               # both spares altered in turn, then new ones
            result = first()
            altered += _alter(result, how)
            del result
        if not altered:
            pytest.skip(f"this numpy does not let {how} be changed in place")
        for _ in range(3):
            result = first()
            assert result.dtype == np.float64 and result.flags.writeable
            assert result.flags.c_contiguous
            assert np.array_equal(result, checked[key])


def test_a_tracer_at_import_switches_recycling_off_rather_than_miscount():
    """A trace function that reads the frames' locals holds one more reference to each
    local: calibrated under it, the count of a free spare would be one too high, and an
    array the caller still holds would be taken for free."""
    script = textwrap.dedent("""
        import sys

        def tracer(frame, event, arg):
            frame.f_locals
            return tracer
        sys.settrace(tracer)
        from mbdyn.algorithms import recycling
        sys.settrace(None)
        print(recycling.FREE)
    """)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out[-1] in (str(recycling.EXPECTED), "-1")
    if recycling.FREE != -1:
        assert out[-1] == "-1"           # the tracer did add one here: not kept
