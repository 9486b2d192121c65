"""What a user assembles: bodies, joints, drives, loads, force elements and effects, each a
plain record validated on creation (every error names the element and says what to
change), and the values they are given: numbers, expressions of parameters, tables,
axes, orientations and inertias.  The tree that connects them is ``mbdyn.assembly``.

Nothing is imported here: ``import mbdyn.elements.bodies`` loads what it needs.
"""
