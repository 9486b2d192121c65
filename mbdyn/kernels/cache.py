"""numba's on-disk cache of the kernels, kept true to their sources.

numba stamps a cached function with a hash of its own source file only.  A kernel that
calls a function of another module carries that callee's compiled code in its cache
entry, so after the callee's module changes (an edited checkout, a ``git pull`` into an
editable install) the caller's entry still loads -- with the old callee in it -- and the
results silently follow the old code.  Seen here: a run's steps depended on which
kernels had been compiled before.

``install`` puts a locator in front of numba's own: for a function defined in mbdyn
(the kernels, and the low-level entries of ``compiled``, which call them) it finds the
place numba would have used (the same folders, the same file names) and stamps the entry
with the file's hash *and* a hash of every module of the kernels, so that a change
anywhere in them recompiles what was compiled from them, on first use, once.  Functions
of other packages are left to numba's locators unchanged.
"""
import hashlib
import os

#: the folder whose modules the stamp covers: the kernels import nothing from outside it
KERNELS = os.path.dirname(os.path.realpath(__file__))
#: the functions stamped so: those defined in any module under this folder
PACKAGE = os.path.dirname(KERNELS)

_FINGERPRINTS = {}


def fingerprint(folder=KERNELS):
    """A hash of the contents of every ``.py`` file in ``folder`` (sorted by name), once
    per process and folder."""
    if folder not in _FINGERPRINTS:
        digest = hashlib.sha256()
        for name in sorted(os.listdir(folder)):
            if name.endswith(".py"):
                with open(os.path.join(folder, name), "rb") as fh:
                    digest.update(name.encode() + b"\0" + fh.read() + b"\0")
        _FINGERPRINTS[folder] = digest.hexdigest()
    return _FINGERPRINTS[folder]


def locator_class(package, sources, fallbacks):
    """A numba cache locator class for the functions defined under the folder
    ``package``: the first of ``fallbacks`` (numba's locator classes) that takes the
    function places the entry, and its stamp adds ``fingerprint(sources)``."""
    package = os.path.join(os.path.realpath(package), "")

    class PackageLocator:
        def __init__(self, inner, py_file):
            self._inner = inner
            self._py_file = py_file              # numba names it in its warnings

        def ensure_cache_path(self):
            self._inner.ensure_cache_path()

        def get_cache_path(self):
            return self._inner.get_cache_path()

        def get_disambiguator(self):
            return self._inner.get_disambiguator()

        def get_source_stamp(self):
            return (self._inner.get_source_stamp(), fingerprint(sources))

        @classmethod
        def from_function(cls, py_func, py_file):
            if not os.path.realpath(py_file).startswith(package):
                return None
            for fallback in fallbacks:
                inner = fallback.from_function(py_func, py_file)
                if inner is not None:
                    return cls(inner, py_file)
            return None

    return PackageLocator


def implementation():
    """numba's class that holds the list of cache locators (``CacheImpl``; ``_CacheImpl``
    before numba 0.60), or None."""
    from numba.core import caching
    return getattr(caching, "CacheImpl", getattr(caching, "_CacheImpl", None))


def install(package=PACKAGE, sources=KERNELS):
    """Put ``locator_class(package, sources, ...)`` first among numba's cache locators
    (once per package).  Without numba's internal list (another numba), leave caching as
    it is."""
    impl = implementation()
    if impl is None:                             # pragma: no cover - another numba
        return
    classes = impl._locator_classes
    package = os.path.realpath(package)
    if any(getattr(c, "package", None) == package for c in classes):
        return
    locator = locator_class(package, sources, list(classes))
    locator.package = package
    classes.insert(0, locator)
