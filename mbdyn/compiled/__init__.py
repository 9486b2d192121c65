"""The compiled, frozen model: its data laid out as flat arrays (``layout``), states by
name (``states``), the force elements packed for their kernel (``force_packing``), drives
and event conditions as programs for compiled code (``programs``), the ``Model`` class
whose methods are the algorithms of ``mbdyn.algorithms`` (``model``), and the low-level
entry for loops of one's own (``lowlevel``).
"""
