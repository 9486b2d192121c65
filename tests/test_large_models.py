"""Large models in O(n) memory (issue 29): a 10,000-body chain and a 5,000-body star
compile and take a step in well under 1 GB and a few seconds, by the articulated-body
route, which needs neither the full Jacobians (n x 3 x nu each) nor ``M`` (nu x nu): they
are allocated on the first use of a route that reads them.  ``benchmarks/large_models.py``
prints the figures.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import mbdyn as mb

#: the package under test, for the subprocesses (not whatever else is installed)
PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(mb.__file__)))

SNIPPET = r"""
import json, resource, sys, time
import mbdyn as mb
from test_large_models import build

def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

kind, n = sys.argv[1], int(sys.argv[2])
mb.simulate(build(kind, 8).compile(), 1e-3, integrator="rk4", dt=1e-3)   # kernels loaded
before = peak_mb()
start = time.perf_counter()
m = build(kind, n).compile()
res = mb.simulate(m, 1e-3, integrator="rk4", dt=1e-3)
print(json.dumps({"seconds": time.perf_counter() - start, "growth_mb": peak_mb() - before,
                  "method": res.stats["method"], "finite": bool((abs(res.u) < 1e300).all()),
                  "full": bool(m._JR.size or m._M.size or m._anc_idx.size)}))
"""


def build(kind, n):
    """A chain (each link hangs from the previous; axes z, y, x in turn: a 3D chain) or a
    star (every link from the ground, about z) of ``n`` revolute links, as
    ``benchmarks/large_models.py`` builds them but for the chain's axes."""
    s = mb.System(f"{kind} {n}", gravity=(0, -9.81, 0))
    parent = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0.1, 0, 0), inertia=(1e-3, 2e-3, 3e-3))
        s.add_joint(f"j{i}", "revolute", parent=parent, child=f"b{i}",
                    axis="z" if kind == "star" else ("z", "y", "x")[i % 3],
                    position=(0.1, 0, 0) if (kind == "chain" and i) else (0, 0, 0.01 * i))
        if kind == "chain":
            parent = f"b{i}"
    return s


@pytest.mark.slow
@pytest.mark.parametrize("kind, n", [("chain", 10_000), ("star", 5_000)])
def test_a_large_model_compiles_and_steps_in_well_under_a_gigabyte(kind, n):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([PACKAGE_ROOT, os.path.dirname(__file__)]))
    out = subprocess.run([sys.executable, "-c", SNIPPET, kind, str(n)], capture_output=True,
                         text=True, timeout=600, env=env, check=False)
    assert out.returncode == 0, out.stderr[-3000:]
    r = json.loads(out.stdout.strip().splitlines()[-1])
    assert r["method"] == "articulated" and r["finite"], r
    assert not r["full"], r                  # no full Jacobians, M or ancestor lists
    # measured 50-60 MB and 1.5-2 s (docs/reliability.md); the bounds leave room for a
    # loaded machine
    assert r["growth_mb"] < 1024, r
    assert r["seconds"] < 60, r


@pytest.mark.parametrize("kind", ["chain", "star"])
def test_the_articulated_route_agrees_with_jourdain_and_needs_no_full_jacobians(kind):
    from mbdyn.algorithms.jourdain import CHECK_BY_CHOLESKY
    assert CHECK_BY_CHOLESKY < 50            # below it, the check at rest allocates them
    m = build(kind, 50).compile()
    rng = np.random.default_rng(29)
    q, u = rng.uniform(-1, 1, m.nq), rng.uniform(-2, 2, m.nu)
    before = m.forward_dynamics(q, u, method="articulated")
    assert m._JR.size == 0 and m._M.size == 0 and m._anc_idx.size == 0
    jourdain = m.forward_dynamics(q, u, method="jourdain")     # allocates them
    assert m._JR.shape == (50, 3, 50) and m._M.shape == (50, 50)
    scale = np.abs(jourdain).max()
    assert np.abs(before - jourdain).max() < 1e-10 * scale
    # the same numbers after the switch, bit for bit, and the full Jacobians filled
    assert np.array_equal(m.forward_dynamics(q, u, method="articulated"), before)
    last = m.frames[-1]
    JR = m.jacobian_rotation(q, last)
    assert np.abs(JR).max() > 0.5
    ll = m.lowlevel("articulated")
    assert np.array_equal(ll.forward_dynamics(q, u), before)


def test_a_singular_large_model_is_named_without_the_mass_matrix():
    """Above 1000 speeds the degree of freedom where the elimination broke down is named
    without ``M`` (nu x nu) and its eigenvalues (O(nu^3))."""
    s = build("chain", 1000)
    s.add_body("end", mass=1.0, com=(0.1, 0, 0), inertia=(1e-3, 2e-3, 3e-3))
    s.add_joint("gimbal", "euler", parent="b999", child="end", sequence="ZXZ")
    m = s.compile()
    with pytest.raises(mb.SingularMassMatrixError, match=r"joint 'gimbal'.*no inertia here"):
        m.forward_dynamics(m.default_coordinates(), np.zeros(m.nu), method="articulated")
    assert m._M.size == 0
