"""The schema of a model file: its sections, the keys each may hold and the kind of value
of each key (``mbdyn.io.value_checks`` checks a value of each kind).
"""
from __future__ import annotations

# value kinds: "string", "name", "expr", "vector", "axis", "inertia", "orientation",
# "names", "paths", "bool", "condition", "direction", "reactions", "pairs", ("choice", options)
MODEL_KEYS = {"name": "string", "description": "string", "gravity": "vector",
              "default_case": "string",
              # a URDF robot the file includes (docs/urdf.md)
              "urdf": "string", "floating": "bool", "accept_inertia": "bool",
              "mesh_path": "paths",
              # the flexible bodies' terms by the compiled function (docs/flexible.md)
              "compiled_terms": "bool"}
BODY_KEYS = {"name": "name", "mass": "expr", "com": "vector", "inertia": "inertia",
             "inertia_about": ("choice", ("com", "origin")), "shape": "shape",
             # a modally reduced flexible body (docs/flexible.md)
             "flexible": "flexible"}
SHAPE_KEYS = {"type": ("choice", ("sphere", "box", "cylinder", "disk", "rod")),
              "radius": "expr", "length": "expr", "size": "vector", "center": "vector",
              "start": "vector", "end": "vector", "axis": "axis", "color": "string"}
JOINT_KINDS = ("revolute", "prismatic", "euler", "spherical", "fixed", "free", "universal",
               "cylindrical", "distance", "coupling")
JOINT_KEYS = {"name": "name", "kind": ("choice", JOINT_KINDS), "parent": "name",
              "child": "name", "axis": "axis", "position": "place",
              "orientation": "orientation", "sequence": "string", "coordinates": "names",
              "speeds": "names", "drive": "expr",
              # loop joints (docs/constraints.md)
              "child_position": "place", "child_orientation": "orientation", "cut": "bool",
              "axis2": "axis", "length": "expr", "follower": "name", "leader": "name",
              "ratio": "expr", "offset": "expr"}
#: the keys that make a joint a loop joint
LOOP_JOINT_KEYS = ("child_position", "child_orientation", "cut", "axis2", "length",
                   "follower", "leader", "ratio", "offset")
LOAD_KEYS = {"name": "name", "body": "name", "force": "vector", "moment": "vector",
             "point": "place", "frame": ("choice", ("world", "body"))}
SIMULATION_KEYS = {"t_end": "expr", "integrator": "string", "method": "string",
                   "rtol": "expr", "atol": "expr", "dt": "expr", "max_step": "expr",
                   "output_dt": "expr", "max_steps": "expr", "max_samples": "expr",
                   "max_wall_time": "expr"}
OUTPUT_KEYS = {"reactions": "reactions", "reactions_frame": ("choice", ("world", "child")),
               "energy": "bool", "points": "points"}
POINT_KEYS = {"frame": "name", "offset": "vector"}
FORCE_KINDS = ("spring-damper", "joint-spring-damper", "bushing", "bearing", "contact",
               "joint-stop")
FORCE_KEYS = {"name": "name", "kind": ("choice", FORCE_KINDS),
              "body_a": "name", "point_a": "place", "body_b": "name", "point_b": "place",
              "body": "name", "point": "place", "housing": "name", "center": "vector",
              "joint": "name", "axis": "axis", "stiffness": "matrix6", "damping": "matrix6",
              "free_length": "expr", "preload": "expr", "rest": "expr", "min_length": "expr",
              "force_table": "table", "damping_table": "table", "law": "expr",
              "interpolation": ("choice", ("pchip", "linear")),
              "speed": "name", "speeds": "exprs",
              "kxx": "coefficient", "kxy": "coefficient", "kyx": "coefficient",
              "kyy": "coefficient", "cxx": "coefficient", "cxy": "coefficient",
              "cyx": "coefficient", "cyy": "coefficient",
              "radius": "expr", "shape": ("choice", ("sphere", "disk")),
              "plane_point": "vector", "plane_normal": "axis", "exponent": "expr",
              "restitution": "expr", "impact_speed": "expr", "friction": "expr",
              "slip_speed": "expr", "lower": "expr", "upper": "expr"}
ACTUATOR_KINDS = ("torque", "motor", "pd", "pid")
ACTUATOR_KEYS = {"name": "name", "joint": "name", "kind": ("choice", ACTUATOR_KINDS),
                 "value": "signal", "setpoint": "signal", "command": "signal",
                 "kp": "expr", "kd": "expr", "ki": "expr", "limit": "expr", "rate": "expr",
                 "anti_windup": "bool", "gravity_compensation": "bool", "feedforward": "bool",
                 "stall_torque": "expr", "no_load_speed": "expr", "torque_speed": "table",
                 "gear": "expr", "rotor_inertia": "expr",
                 "interpolation": ("choice", ("pchip", "linear"))}
#: contact shapes and contacts between them (docs/contact.md); not the drawing shape of a body
CONTACT_SHAPE_KEYS = {"name": "name", "kind": ("choice", ("sphere", "plane", "box", "capsule",
                                                          "cylinder", "cam")),
                      "body": "name", "position": "vector", "radius": "expr", "normal": "axis",
                      "half_sizes": "vector", "sizes": "vector", "orientation": "orientation",
                      "length": "expr", "axis": "axis", "profile": "table"}
CONTACT_KEYS = {"name": "name", "pairs": "pairs", "group": "names", "stiffness": "expr",
                "exponent": "expr", "restitution": "expr", "impact_speed": "expr",
                "friction": "expr", "slip_speed": "expr", "broad_phase": "bool"}
EFFECT_KEYS = {"gravity": "bool", "gyroscopic": "bool", "off": "names", "on": "names"}
EVENT_KEYS = {"name": "name", "condition": "condition", "terminal": "bool",
              "direction": "direction",
              # instead of a condition: the gap of a contact (docs/contact.md)
              "contact": "names"}

#: section -> (layout, keys): "table" (fixed keys), "map" (any names -> expr),
#: "array" (array of tables with a name each)
SECTIONS = {
    "model": ("table", MODEL_KEYS),
    "parameters": ("map", None),
    "bodies": ("array", BODY_KEYS),
    "joints": ("array", JOINT_KEYS),
    "loads": ("array", LOAD_KEYS),
    "forces": ("array", FORCE_KEYS),
    "actuators": ("array", ACTUATOR_KEYS),
    "shapes": ("array", CONTACT_SHAPE_KEYS),
    "contacts": ("array", CONTACT_KEYS),
    "effects": ("table", EFFECT_KEYS),
    "initial": ("map", None),
    "initial_speeds": ("map", None),
    "guess": ("map", None),
    "simulation": ("table", SIMULATION_KEYS),
    "outputs": ("table", OUTPUT_KEYS),
    "events": ("array", EVENT_KEYS),
    "cases": ("cases", None),
}
ARRAY_ELEMENT = {"bodies": "body", "joints": "joint", "loads": "load", "forces": "force",
                 "actuators": "actuator", "shapes": "shape", "contacts": "contact",
                 "events": "event"}
DIRECTIONS = {"rising": 1, "falling": -1, "either": 0}
