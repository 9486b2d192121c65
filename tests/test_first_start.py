"""``import mbdyn`` is cheap: no heavy library, no compilation; the public names still
resolve on first use (docs/performance.md, "Cold and warm start")."""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

PROBE = r"""
import json, sys
import mbdyn as mb
heavy = [m for m in ("numba", "sympy", "scipy", "matplotlib", "dask", "networkx")
         if m in sys.modules]
compiled = []
for name, mod in list(sys.modules.items()):
    if name.startswith("mbdyn."):
        for attr, obj in vars(mod).items():
            if getattr(obj, "signatures", None):
                compiled.append(f"{name}.{attr}")
names = {n: type(getattr(mb, n)).__name__ for n in ("derive", "viz", "sweep", "simulate",
                                                      "System", "forces", "errors")}
names["Result.plot"] = callable(mb.Result.plot)
names["Result.animate"] = callable(mb.Result.animate)
print(json.dumps({"heavy": heavy, "compiled": compiled, "names": names,
                  "all": sorted(set(mb.__all__) - set(dir(mb)))}))
"""


def probe():
    out = subprocess.run([sys.executable, "-c", PROBE], cwd=ROOT, capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout)


def test_import_mbdyn_imports_no_heavy_library_and_compiles_nothing():
    got = probe()
    assert got["heavy"] == []
    assert got["compiled"] == []


def test_public_names_still_resolve_lazily():
    names = probe()["names"]
    assert names == {"derive": "function", "viz": "module", "sweep": "function",
                     "simulate": "function", "System": "type", "forces": "module",
                     "errors": "module", "Result.plot": True, "Result.animate": True}


def test_every_name_in_all_is_listed_and_imports():
    import mbdyn as mb
    assert probe()["all"] == []
    for name in mb.__all__:
        assert getattr(mb, name) is not None


def test_simulate_stays_the_function_after_its_module_is_imported():
    import mbdyn as mb
    import mbdyn.integrate.simulation  # noqa: F401  (the module that defines it)
    assert callable(mb.simulate) and mb.simulate.__name__ == "simulate"


RUN_PROBE = r"""
import json, sys
from mbdyn.cli import main
code = main(["run", "models/top.toml", "--case", "a", "--t-end", "0.05", "--json"])
compiled = sorted(f"{name}.{attr}" for name, mod in list(sys.modules.items())
                  if name.startswith("mbdyn.kernels.")
                  for attr, obj in vars(mod).items() if getattr(obj, "signatures", None))
print(json.dumps({"code": code, "compiled": compiled, "modules": sorted(
    m for m in ("mbdyn.symbolic", "mbdyn.analysis", "mbdyn.viz", "scipy.integrate",
                "scipy.optimize", "matplotlib") if m in sys.modules)}))
"""


def test_a_fixed_step_run_loads_and_compiles_only_what_it_uses():
    """``mbdyn run`` of the top (semi-implicit Euler, no force elements, reactions at the
    output points) imports no other command's layers nor scipy's integrators, and neither
    compiles nor loads the force-element kernel or the fused Newton-Euler solution."""
    out = subprocess.run([sys.executable, "-c", RUN_PROBE], cwd=ROOT, capture_output=True,
                         text=True, check=True)
    got = json.loads(out.stdout.splitlines()[-1])
    assert got["code"] == 0
    assert got["modules"] == []
    assert "mbdyn.kernels.integrators.semi_implicit_euler_loop" in got["compiled"]
    for name in ("mbdyn.kernels.forces.force_elements",
                 "mbdyn.kernels.evaluate.newton_euler_solution",
                 "mbdyn.kernels.integrators.rk4_loop"):
        assert name not in got["compiled"]
