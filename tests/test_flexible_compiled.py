"""The compiled flexible terms (``FlexibleModel.compiled_terms``, opt-in) against numpy's
route (``algorithms.flexible_dynamics``, ``flexible_loops``), the reference: the same
``M``, ``f``, ``A``, ``u'``, multipliers and projection to 1e-12 on a free-floating, a
spinning, a driven (gyroscopic off), a tip-loaded and a force-element model and on a
flexible slider-crank; and the same runs by the compiled loops as by the Python loops.

The compiled function costs 20 to 70 s of CPU per kind of model on a cold numba cache
(``docs/flexible.md``, "Routes and cost"), hence ``slow``; with the cache warm, seconds.
"""
import numpy as np
import pytest

import mbdyn as mb
from mbdyn.algorithms import flexible_dynamics as fd
from mbdyn.algorithms import flexible_kernels as fk
from mbdyn.algorithms import flexible_loops as fl

STEEL = {"length": 1.0, "elements": 8, "E": 2.1e11, "rho": 7850.0, "nu": 0.3,
         "section": {"circle": 0.02}}
ALU = {"length": 1.0, "elements": 8, "E": 7e10, "rho": 2700.0, "rect": [0.03, 0.02]}


def _free():
    s = mb.System("free beam", gravity=(0, 0, 0))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 4})
    s.add_joint("float", "free", "ground", "shaft")
    return s.compile()


def _spinning():
    s = mb.System("spin", gravity=(0, 0, -9.81))
    s.add_body("hub", mass=2.0, inertia=[0.1, 0.1, 0.1])
    s.add_joint("spin", "revolute", "ground", "hub", axis="z")
    s.add_body("blade", flexible={"beam": {**ALU, "theory": "timoshenko"}, "modes": 3,
                                  "damping": 0.02})
    s.add_joint("root", "fixed", "hub", "blade", position=(0.1, 0, 0))
    return s.compile()


def _driven():
    s = mb.System("driven", gravity=(0, -9.81, 0))
    s.add_body("arm", flexible={"beam": ALU, "modes": 3})
    s.add_joint("pin", "revolute", "ground", "arm", axis="z",
                drive=2.0 * mb.t + 0.3 * mb.t ** 2)
    return s.compile(effects="-gyroscopic")


def _tip_loaded():
    s = mb.System("pinned beam", gravity=(0, -9.81, 0))
    s.add_body("beam", flexible={"beam": ALU, "modes": 3})
    s.add_joint("pin", "spherical", "ground", "beam")
    s.add_body("bob", mass=0.5, com=(0, -0.2, 0), inertia=[1e-3] * 3)
    s.add_joint("hang", "revolute", "beam", "bob", axis="z", position=[0.97, 0.0, 0.01])
    return s.compile()


def _elements(gyroscopic=True, damper=True):
    s = mb.System("elements", gravity=(0, 0, -9.81))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 5, "damping": 0.01})
    s.add_joint("pin", "revolute", "ground", "shaft", axis="y")
    s.add_body("box", mass=1.0, inertia=[0.1, 0.1, 0.1])
    s.add_joint("slide", "prismatic", "ground", "box", axis="z", position=[1.0, 0, -0.5])
    s.add_load("push", "shaft", force=(0, 1.0, -5.0), moment=(0.1, 0.2, 0.3), point="tip",
               frame="body")
    if damper:
        s.add_force("spring", "spring-damper", body_a="shaft", point_a=[0.53, 0.01, 0.0],
                    body_b="box", point_b=[0, 0, 0], stiffness=500.0, damping=3.0,
                    preload=2.0, free_length=0.4)
    s.add_force("mount", "bushing", body_a="shaft", point_a="tip", body_b="ground",
                point_b=[1.0, 0, 0], stiffness=[1e4, 2e4, 3e4, 10, 20, 30],
                damping=[1, 2, 3, 0.1, 0.2, 0.3])
    return s.compile(effects=None if gyroscopic else "-gyroscopic")


def _slider_crank():
    rod = {"theory": "euler-bernoulli", "length": 0.3, "elements": 6, "E": 2e11,
           "rho": 7870.0, "rect": [0.008, 0.008]}
    s = mb.System("flexible slider-crank", gravity=(0, 0, 0))
    s.add_body("crank", mass=0.36, com=(0.075, 0, 0), inertia=[1e-4, 1e-3, 1e-3])
    s.add_joint("phi1", "revolute", "ground", "crank", axis="z", drive=150.0 * mb.t)
    s.add_body("rod", flexible={"beam": rod, "modes": 3})
    s.add_joint("phi2", "revolute", "crank", "rod", axis="z", position=(0.15, 0, 0))
    s.add_body("slider", mass=0.076, inertia=[1e-5, 1e-5, 1e-5])
    s.add_joint("x3", "prismatic", "ground", "slider", axis="x")
    s.add_joint("B", "revolute", "rod", "slider", axis="z", position="tip",
                child_position=(0, 0, 0))
    return s.compile()


OPEN = {"free": _free, "spinning": _spinning, "driven": _driven, "tip": _tip_loaded,
        "elements": _elements}


def _rel(a, b):
    return np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)


def _state(m, rng, scale=0.02):
    q = m.default_coordinates() + rng.normal(size=m.nq) * scale
    m.normalize_quaternions(q)
    return q, rng.normal(size=m.nu) * scale * 10


def test_compiled_terms_are_opt_in():
    m = _tip_loaded()
    assert not m.compiled_terms and m.has_callable_loads      # numpy's route, scipy
    m.compiled_terms = True
    assert m.compiled_terms and not m.has_callable_loads      # the compiled loops


@pytest.mark.filterwarnings("ignore:.*gyroscopic effect is off")
def test_elements_read_the_true_speeds_with_the_gyroscopic_effect_off():
    """A damper's force does not depend on the gyroscopic switch: its share of ``f``
    (with minus without it) is the same with the effect on and off (numpy's route)."""
    rng = np.random.default_rng(3)
    on, off = _elements(True, True), _elements(False, True)
    on0, off0 = _elements(True, False), _elements(False, False)
    for _ in range(3):
        q, u = _state(on, rng)
        share_on = fd.forcing(on, q, u) - fd.forcing(on0, q, u)
        share_off = fd.forcing(off, q, u) - fd.forcing(off0, q, u)
        assert np.abs(share_on).max() > 1.0
        assert _rel(share_off, share_on) < 1e-12


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:.*gyroscopic effect is off")
@pytest.mark.parametrize("name", sorted(OPEN))
def test_compiled_terms_equal_numpys(name):
    m = OPEN[name]()
    m.compiled_terms = True
    rng = np.random.default_rng(7)
    for trial in range(3):
        q, u = _state(m, rng)
        t = 0.013 * trial
        for a, b in zip(fk.terms(m, q, u, t), fd.terms(m, q, u, t)):
            assert _rel(a, b) < 1e-12
        assert _rel(m.forward_dynamics(q, u, t), fd.forward_dynamics(m, q, u, t)) < 1e-12


@pytest.mark.slow
def test_compiled_loop_terms_and_projection_equal_numpys():
    m = _slider_crank()
    m.compiled_terms = True
    rng = np.random.default_rng(5)
    q0, u0 = m.assemble(initial_speeds=dict.fromkeys(m.modal_coordinates, 0.0),
                        guess={"phi2": -0.2, "x3": 0.42}, t=0.0)
    for trial in range(3):
        q = q0 + rng.normal(size=m.nq) * 1e-3
        u = u0 + rng.normal(size=m.nu) * 1e-2
        t = 0.001 * trial
        qa, ua = m.project(q, u, t)
        qb, ub = fl.project(m, q, u, t)
        assert _rel(qa, qb) < 1e-12 and _rel(ua, ub) < 1e-12
        uda, lama = m.multipliers(qa, ua, t)
        udb, lamb = fl.constrained_accelerations(m, qa, ua, t)
        assert _rel(uda, udb) < 1e-12 and _rel(lama, lamb) < 1e-12


@pytest.mark.slow
def test_compiled_loops_run_as_the_python_loops():
    m = _slider_crank()
    q0, u0 = m.assemble(initial_speeds=dict.fromkeys(m.modal_coordinates, 0.0),
                        guess={"phi2": -0.2, "x3": 0.42}, t=0.0)
    runs = []
    for on in (False, True):
        m.compiled_terms = on
        runs.append(mb.simulate(m, 0.002, q0, u0, integrator="rk4", dt=2e-6))
    py, comp = runs
    assert not py.stats["compiled_loop"] and comp.stats["compiled_loop"]
    assert _rel(comp.q[-1], py.q[-1]) < 1e-12 and _rel(comp.u[-1], py.u[-1]) < 1e-10


@pytest.mark.slow
def test_compiled_free_floating_beam_conserves_energy_and_momentum():
    s = mb.System("free", gravity=(0, 0, 0))
    s.add_body("shaft", flexible={"beam": STEEL, "modes": 4})
    s.add_joint("float", "free", "ground", "shaft")
    m = s.compile(effects="-geometric_stiffening")
    m.compiled_terms = True
    u0 = {"float_vx": 0.3, "float_vy": -0.2, "float_wx": 1.0, "float_wy": 2.0,
          "float_wz": 3.0, "shaft_m1_dot": 0.05}
    res = mb.simulate(m, 0.05, {"shaft_m1": 1e-3, "shaft_m3": -5e-4}, u0, rtol=1e-10,
                      atol=1e-12, outputs=("energy", "momentum"),
                      t_eval=np.linspace(0, 0.05, 101))
    assert res.stats["compiled"]
    E = res.energy["total"]
    assert np.abs(E - E[0]).max() / E[0] < 1e-9
    L = res.momentum["angular"]
    assert np.abs(L - L[0]).max() < 1e-9 * np.abs(L[0]).max()


def test_batched_sweeps_refuse_the_compiled_terms():
    """The compiled terms' workspace is the model's: members on threads would share it."""
    from types import SimpleNamespace

    from mbdyn.analysis.sweeps.batched import batchable
    m = _tip_loaded()
    scene = SimpleNamespace(model=m, settings={"integrator": "rk4", "method": "jourdain"},
                            events=())
    assert "Python-function loads" in batchable(scene, ["final"])    # numpy's terms
    m.compiled_terms = True
    assert "one workspace" in batchable(scene, ["final"])


def test_contacts_between_shapes_keep_numpys_terms():
    s = mb.System("contact", gravity=(0, 0, -9.81))
    s.add_body("arm", flexible={"beam": ALU, "modes": 2})
    s.add_joint("pin", "revolute", "ground", "arm", axis="y")
    for k in range(2):
        s.add_body(f"b{k}", mass=1.0, inertia=[1e-3] * 3)
        s.add_joint(f"f{k}", "free", "ground", f"b{k}", position=(0, 0, 0.3 * k))
        s.add_shape(f"s{k}", "sphere", f"b{k}", radius=0.1)
    s.add_contact("c", pairs=[("s0", "s1")], stiffness=1e7)
    m = s.compile()
    with pytest.raises(mb.ModelError, match="contacts between shapes"):
        m.compiled_terms = True
    assert not m.compiled_terms and m.has_callable_loads


def test_model_file_key_chooses_the_compiled_terms():
    """``[model] compiled_terms = true`` (here by ``--set``) sets the flexible model's
    ``compiled_terms`` (nothing is compiled before a first evaluation); off by default; a
    warning naming the key on a model without flexible bodies; a value that is not a
    boolean is refused with the key named."""
    on = mb.load_model("models/flexible_pendulum.toml",
                       overrides=["model.compiled_terms=true"])
    assert on.model.compiled_terms is True
    assert mb.load_model("models/flexible_pendulum.toml").model.compiled_terms is False
    with pytest.warns(mb.ModelWarning, match=r"\[model\] compiled_terms.*no flexible"):
        mb.load_model("models/double_pendulum.toml", overrides=["model.compiled_terms=true"])
    with pytest.raises(mb.ModelError, match="compiled_terms.*true or false"):
        mb.load_model("models/flexible_pendulum.toml", overrides=["model.compiled_terms=3"])
