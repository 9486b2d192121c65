"""Pictures of results: time series and phase portraits, animations (GIF, MP4) and a
self-contained HTML view.

Reads a ``Result`` and the ``Model``'s geometry; never reaches into the kernels.
matplotlib is imported only when a picture is asked for (extras ``plot``, ``viz``,
``video``); the HTML view needs no library (its viewer is ``view.js``).
"""
from .animate import animate, snapshot
from .plots import SERIES_HELP, plot_result, series_table

__all__ = ["plot_result", "series_table", "SERIES_HELP", "animate", "snapshot"]
