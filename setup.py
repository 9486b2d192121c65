"""The build of mbdyn's one C extension, ``mbdyn.kernels._fastcall`` (everything else is in
pyproject.toml): the two hottest per-call methods at the cost of one C call
(``mbdyn/kernels/fastcall.py``).  Optional: where it cannot be compiled (no C compiler),
mbdyn installs without it and those methods take their Python route."""
from setuptools import Extension, setup

try:                            # its headers (pyproject.toml's build requirements)
    import numpy
except ImportError:             # a build without isolation and without numpy: no extension
    numpy = None

setup(ext_modules=[] if numpy is None else [
    Extension("mbdyn.kernels._fastcall", ["mbdyn/kernels/_fastcall.c"],
              include_dirs=[numpy.get_include()], optional=True)])
