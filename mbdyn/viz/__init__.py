"""Pictures of results: time series and phase portraits (matplotlib, Agg: no display).

Reads a ``Result`` and the ``Model``'s names; never reaches into the kernels.  matplotlib is
imported only when a picture is asked for (``pip install "mbdyn[plot]"``).
"""
from .plots import SERIES_HELP, plot_result, series_table

__all__ = ["plot_result", "series_table", "SERIES_HELP"]
