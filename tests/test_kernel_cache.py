"""numba's on-disk cache kept true to the kernels' sources (``kernels.cache``).

numba stamps a cached function with its own file only, so a caller's cache entry, which
holds its callees' compiled code, outlives a change to a callee in another module.  The
package's locator adds a hash of every kernel module to the stamp: a changed callee
recompiles its callers.
"""
import os
import subprocess
import sys
import textwrap

import mbdyn.kernels  # noqa: F401  (installs the locator)
from mbdyn.kernels import cache
from mbdyn.kernels import inverse

RUN = textwrap.dedent("""
    import sys
    from mbdyn.kernels.cache import install
    install(package=sys.argv[1], sources=sys.argv[1])
    sys.path.insert(0, sys.argv[2])
    from pkg.caller import f
    print(f(1.0))
""")


def write(folder, name, text):
    with open(os.path.join(folder, name), "w") as fh:
        fh.write(textwrap.dedent(text))


def run(pkg, root):
    out = subprocess.run([sys.executable, "-c", RUN, pkg, root], capture_output=True,
                         text=True, timeout=300, env={**os.environ, "NUMBA_CACHE_DIR": ""})
    assert out.returncode == 0, out.stderr
    return float(out.stdout.split()[-1])


def test_a_changed_callee_in_another_module_recompiles_its_cached_caller(tmp_path):
    """Two processes, as two sessions: the first compiles and caches ``f``, which calls
    ``g`` of another module; ``g`` is then changed and ``f``'s own file is not.  numba's
    locators alone load ``f``'s old entry (4.0 again, seen with numba 0.68); stamped with
    the package's modules, the second session recompiles and gives the new answer."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    write(pkg, "__init__.py", "")
    write(pkg, "callee.py", """
        from numba import njit

        @njit(cache=True)
        def g(x):
            return x + 1.0
    """)
    write(pkg, "caller.py", """
        from numba import njit
        from .callee import g

        @njit(cache=True)
        def f(x):
            return 2.0 * g(x)
    """)
    assert run(str(pkg), str(tmp_path)) == 4.0
    assert any(n.endswith(".nbi") for n in os.listdir(pkg / "__pycache__"))  # cached
    write(pkg, "callee.py", """
        from numba import njit

        @njit(cache=True)
        def g(x):
            return x + 100.0
    """)
    assert run(str(pkg), str(tmp_path)) == 202.0
    assert run(str(pkg), str(tmp_path)) == 202.0      # and cached again as it now is


def test_the_fingerprint_follows_every_module_of_the_folder(tmp_path):
    write(tmp_path, "a.py", "x = 1\n")
    write(tmp_path, "b.py", "y = 2\n")
    write(tmp_path, "notes.txt", "not a module\n")
    first = cache.fingerprint(str(tmp_path))
    assert cache.fingerprint(str(tmp_path)) == first
    cache._FINGERPRINTS.clear()
    write(tmp_path, "notes.txt", "changed, still not a module\n")
    assert cache.fingerprint(str(tmp_path)) == first
    cache._FINGERPRINTS.clear()
    write(tmp_path, "b.py", "y = 3\n")
    assert cache.fingerprint(str(tmp_path)) != first
    cache._FINGERPRINTS.clear()


def test_mbdyn_kernels_are_stamped_with_the_kernel_sources():
    locator = cache.implementation()._locator_classes[0]
    assert locator.package == os.path.realpath(cache.PACKAGE)
    kernel = inverse.mass_matrix_packed
    used = kernel._cache._impl.locator
    assert isinstance(used, locator)
    stamp = used.get_source_stamp()
    assert stamp[1] == cache.fingerprint(cache.KERNELS)
    # another package's function is left to numba's own locators
    assert locator.from_function(textwrap.dedent, textwrap.__file__) is None


def test_the_compile_notice_reads_the_same_fingerprint_without_importing_numba():
    """``mbdyn.cli.compiling`` decides whether a command will compile before numba is
    imported, so it hashes the kernel modules itself: the same hash as the stamp's; and
    a kernel that has been loaded from or saved to the cache counts as cached."""
    from mbdyn.cli import compiling
    assert compiling.kernels_fingerprint() == cache.fingerprint()
    import numpy as np
    from mbdyn.kernels import dynamics
    M, f = np.array([[4.0, 2.0], [2.0, 3.0]]), np.array([2.0, 1.0])
    x = np.empty(2)
    dynamics.cholesky_solve(M, f, np.empty((2, 2)), x)   # compiled or loaded: cached
    assert np.allclose(M @ x, f)
    assert compiling.is_cached("dynamics", "cholesky_solve")
