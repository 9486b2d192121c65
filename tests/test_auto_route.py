"""The ordinary API takes the fast route by default (issue 25, item 9): ``method="auto"``
is ``Model.formulation("auto")``, Jourdain below ``ARTICULATED_FROM`` free speeds, the
articulated bodies above."""
import numpy as np

import mbdyn as mb
from mbdyn.algorithms.forward_dynamics import ARTICULATED_FROM


def chain(n):
    s = mb.System("chain")
    prev = "ground"
    for i in range(n):
        s.add_body(f"b{i}", mass=1.0, com=(0.5, 0, 0), inertia=(0.01, 0.1, 0.1))
        s.add_joint(f"j{i}", "revolute", parent=prev, child=f"b{i}", axis="y",
                    position=(1.0 if i else 0, 0, 0))
        prev = f"b{i}"
    return s.compile(check_inertia=False)


def test_default_route_is_the_measured_crossover():
    rng = np.random.default_rng(1)
    for n, route in ((3, "jourdain"), (ARTICULATED_FROM + 4, "articulated")):
        m = chain(n)
        assert m.formulation("auto") == route
        q, u = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        default = m.forward_dynamics(q, u)
        assert np.array_equal(default, m.forward_dynamics(q, u, method=route))
        other = "articulated" if route == "jourdain" else "jourdain"
        assert np.allclose(default, m.forward_dynamics(q, u, method=other), rtol=1e-9,
                           atol=1e-9)
        y = np.concatenate([q, u])
        assert np.array_equal(m.state_derivative(0.0, y),
                              m.state_derivative(0.0, y, method=route))
