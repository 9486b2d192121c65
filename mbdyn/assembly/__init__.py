"""What a user assembles, as a whole: the ``System`` holds the elements (``mbdyn.elements``)
in a networkx tree of frames and joints, validates what concerns more than one element,
and compiles it to a frozen ``Model`` (``mbdyn.compiled``).  Loop constraints will be found
here too (a spanning tree and its cycle basis).
"""
