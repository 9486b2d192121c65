"""A URDF file's XML, read by a hardened parser (``defusedxml``) into plain records.

Malformed XML, entity declarations (an entity bomb such as "billion laughs", or an
external entity that would read another file) and external references are refused
before anything is expanded.  What is read, each value checked (finite numbers within
``mbdyn.limits``): ``<link>`` (``<inertial>``: ``<origin>``, ``<mass>``, ``<inertia>``;
``<visual>``: ``<origin>``, ``<geometry>`` (mesh filename and scale, box, cylinder,
sphere), ``<material>`` colour, its own or a top-level ``<material>``'s; ``<collision>``
counted), ``<joint>`` (``<origin>``, ``<parent>``,
``<child>``, ``<axis>``, ``<limit>``, ``<dynamics>``, ``<mimic>``), ``<transmission>``
(its type, joints, actuators and their reductions).  Every other tag is counted in
``Robot.not_used`` (``mbdyn info`` and a warning name it).  Errors are
``ModelFileError``s naming the file and the link or joint.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from xml.etree.ElementTree import ParseError

from ... import limits
from ..errors import ModelFileError

#: joint types of the URDF specification
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: tags read for the dynamics
_LINK_TAGS = ("inertial", "visual", "collision")
_JOINT_TAGS = ("origin", "parent", "child", "axis", "limit", "dynamics", "mimic")
#: tags the specification defines that carry nothing for the dynamics
_JOINT_NOT_USED = ("calibration", "safety_controller")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


@dataclass
class Inertial:
    xyz: tuple
    rpy: tuple
    mass: float
    inertia: tuple | None            # (ixx, ixy, ixz, iyy, iyz, izz), or None if absent


@dataclass
class Visual:
    kind: str                        # "mesh", "box", "cylinder", "sphere" (else "none")
    xyz: tuple = (0.0, 0.0, 0.0)
    rpy: tuple = (0.0, 0.0, 0.0)
    values: dict = field(default_factory=dict)   # filename, scale; size; radius, length
    color: str | None = None         # "#rrggbb" of the material's rgba, if given


@dataclass
class Link:
    name: str
    inertial: Inertial | None
    visuals: list = field(default_factory=list)      # Visual records, in file order


@dataclass
class Joint:
    name: str
    type: str
    parent: str
    child: str
    xyz: tuple = (0.0, 0.0, 0.0)
    rpy: tuple = (0.0, 0.0, 0.0)
    axis: tuple = (1.0, 0.0, 0.0)
    limit: dict | None = None        # lower, upper, effort, velocity (those given)
    dynamics: dict | None = None     # damping, friction (those given)
    mimic: dict | None = None        # joint, multiplier, offset


@dataclass
class Robot:
    name: str
    links: dict                      # name -> Link, in file order
    joints: dict                     # name -> Joint, in file order
    transmissions: list              # {name, type, joints, actuators}
    not_used: dict                   # tag (as "link/collision") -> count


class Reader:
    """Reads one URDF document; ``error(where, problem)`` names the file."""

    def __init__(self, file):
        self.file = str(file)
        self.not_used = {}
        self.materials = {}          # top-level <material name>: "#rrggbb"

    def error(self, where, problem):
        return ModelFileError(self.file, where, problem)

    def skip(self, tag, count=1):
        self.not_used[tag] = self.not_used.get(tag, 0) + count

    # -- values
    def number(self, text, where, what):
        if text is None or not _NUMBER.fullmatch(text.strip()):
            raise self.error(where, f"{what} must be a number, got {_show(text)}")
        value = float(text)
        if not math.isfinite(value):
            raise self.error(where, f"{what} is not a finite number ({_show(text)})")
        problem = limits.magnitude_problem(value)
        if problem:
            raise self.error(where, f"{what}: {problem}")
        return value

    def numbers(self, text, count, where, what, default):
        if text is None:
            return default
        parts = text.split()
        if len(parts) != count:
            raise self.error(where, f"{what} must be {count} numbers separated by spaces, "
                             f"got {_show(text)}")
        return tuple(self.number(p, where, what) for p in parts)

    def attribute(self, element, key, where):
        value = element.get(key)
        if value is None or not value.strip():
            raise self.error(where, f"<{element.tag}> needs the attribute {key}=\"...\"")
        return value.strip()

    def origin(self, element, where):
        """``(xyz, rpy)`` of the ``<origin>`` child of ``element`` (zeros if absent)."""
        found = element.findall("origin")
        if len(found) > 1:
            raise self.error(where, "has more than one <origin>; keep one")
        if not found:
            return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        o = found[0]
        return (self.numbers(o.get("xyz"), 3, where, "origin xyz", (0.0, 0.0, 0.0)),
                self.numbers(o.get("rpy"), 3, where, "origin rpy", (0.0, 0.0, 0.0)))

    # -- elements
    def link(self, element):
        name = self.attribute(element, "name", "<link>")
        where = f"link {name!r}"
        inertial = None
        found = element.findall("inertial")
        if len(found) > 1:
            raise self.error(where, "has more than one <inertial>; keep one")
        if found:
            inertial = self.inertial(found[0], where)
        visuals = []
        for child in element:
            if child.tag == "visual":
                visuals.append(self.visual(child, where))
            elif child.tag == "collision":
                self.skip(f"link/{child.tag}")
            elif child.tag not in _LINK_TAGS:
                self.skip(f"link/{_tag(child)}")
        return Link(name, inertial, visuals)

    def visual(self, element, where):
        """A ``<visual>``'s ``Visual``: its origin, geometry and colour."""
        where = where + ": <visual>"
        xyz, rpy = self.origin(element, where)
        geometry = element.find("geometry")
        shapes = [g for g in geometry if isinstance(g.tag, str)] if geometry is not None \
            else []
        visual = Visual(shapes[0].tag if shapes else "none", xyz, rpy)
        g, values = (shapes[0] if shapes else None), visual.values
        if visual.kind == "mesh":
            values["filename"] = self.attribute(g, "filename", where)
            values["scale"] = self.numbers(g.get("scale"), 3, where, "mesh scale",
                                           (1.0, 1.0, 1.0))
        elif visual.kind == "box":
            values["size"] = self.numbers(self.attribute(g, "size", where), 3, where,
                                          "box size", None)
        elif visual.kind in ("cylinder", "sphere"):
            for key in ("radius", "length") if visual.kind == "cylinder" else ("radius",):
                values[key] = self.number(self.attribute(g, key, where), where,
                                          f"{visual.kind} {key}")
        material = element.find("material")
        if material is not None:
            visual.color = self.colour(material, where) or \
                self.materials.get(material.get("name", "").strip())
        return visual

    def colour(self, material, where):
        """``"#rrggbb"`` of a ``<material>``'s ``<color rgba>`` (``None`` without one)."""
        found = material.find("color")
        if found is None or found.get("rgba") is None:
            return None
        rgba = self.numbers(found.get("rgba"), 4, where, "color rgba", None)
        return "#" + "".join(f"{round(255 * min(max(c, 0.0), 1.0)):02x}" for c in rgba[:3])

    def inertial(self, element, where):
        xyz, rpy = self.origin(element, where + ": <inertial>")
        mass_el = element.find("mass")
        if mass_el is None:
            raise self.error(where, "<inertial> has no <mass value=\"...\"/>; give the "
                             "link's mass (or remove <inertial> for a massless link)")
        mass = self.number(mass_el.get("value"), where, "<mass> value")
        if mass < 0:
            raise self.error(where, f"<mass> value {mass:g} is negative; a mass is >= 0")
        inertia_el = element.find("inertia")
        inertia = None
        if inertia_el is not None:
            inertia = tuple(self.number(inertia_el.get(k), where, f"<inertia> {k}")
                            for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
        return Inertial(xyz, rpy, mass, inertia)

    def joint(self, element):
        name = self.attribute(element, "name", "<joint>")
        where = f"joint {name!r}"
        kind = self.attribute(element, "type", where)
        if kind not in JOINT_TYPES:
            from ..wording import suggest
            raise self.error(where, f"unknown joint type {_show(kind)}; "
                             f"{suggest(kind, JOINT_TYPES)}URDF's types are: "
                             f"{', '.join(JOINT_TYPES)}")
        links = {}
        for role in ("parent", "child"):
            found = element.findall(role)
            if len(found) != 1:
                raise self.error(where, f"needs exactly one <{role} link=\"...\"/>, has "
                                 f"{len(found)}")
            links[role] = self.attribute(found[0], "link", where)
        xyz, rpy = self.origin(element, where)
        joint = Joint(name, kind, links["parent"], links["child"], xyz, rpy)
        axis = element.find("axis")
        if axis is not None:
            joint.axis = self.numbers(axis.get("xyz"), 3, where, "axis xyz", (1.0, 0.0, 0.0))
        for tag, keys in (("limit", ("lower", "upper", "effort", "velocity")),
                          ("dynamics", ("damping", "friction")),
                          ("mimic", ("multiplier", "offset"))):
            el = element.find(tag)
            if el is not None:
                setattr(joint, tag, {k: self.number(el.get(k), where, f"<{tag}> {k}")
                                     for k in keys if el.get(k) is not None})
        if joint.mimic is not None:
            joint.mimic["joint"] = self.attribute(element.find("mimic"), "joint", where)
        for child in element:
            if child.tag in _JOINT_NOT_USED or child.tag not in _JOINT_TAGS:
                self.skip(f"joint/{_tag(child)}")
        return joint

    def transmission(self, element):
        """A ``<transmission>``'s name, type, joints and actuators, as written (both the
        old form, ``type`` an attribute, and the new, ``<type>`` a child)."""
        name = element.get("name", "").strip() or "(unnamed)"
        type_el = element.find("type")
        kind = (type_el.text or "").strip() if type_el is not None else element.get("type", "")

        def texts(parent, tag):
            return [(e.text or "").strip() for e in parent.findall(tag)]
        joints = [{"name": j.get("name", ""), "interfaces": texts(j, "hardwareInterface")}
                  for j in element.findall("joint")]
        actuators = [{"name": a.get("name", ""), "interfaces": texts(a, "hardwareInterface"),
                      "reduction": (texts(a, "mechanicalReduction") or [""])[0]}
                     for a in element.findall("actuator")]
        return {"name": name, "type": kind, "joints": joints, "actuators": actuators}


def _tag(element):
    """A tag as written, a namespace shown as its prefix would be (``{uri}name`` ->
    ``name``)."""
    tag = element.tag if isinstance(element.tag, str) else "(comment)"
    return tag.rsplit("}", 1)[-1]


def _show(text):
    text = "" if text is None else str(text)
    return repr(text if len(text) < 60 else text[:56] + "...")


def parse_urdf(data, file):
    """The ``Robot`` of a URDF document ``data`` (bytes or text); ``file`` names it in
    messages."""
    import defusedxml.ElementTree as safe
    from defusedxml import DefusedXmlException, DTDForbidden, EntitiesForbidden
    reader = Reader(file)
    try:
        root = safe.fromstring(data, forbid_dtd=False, forbid_entities=True,
                               forbid_external=True)
    except EntitiesForbidden as exc:
        raise reader.error("", f"declares the XML entity {_show(exc.name)}: entities can "
                           "expand into gigabytes (an entity bomb) or read other files "
                           "(an external entity); URDF needs none, so the file is refused "
                           "unread") from None
    except (DTDForbidden, DefusedXmlException) as exc:
        raise reader.error("", f"refers to an external resource ({type(exc).__name__}); "
                           "URDF needs none, so the file is refused unread") from None
    except ParseError as exc:
        line, column = getattr(exc, "position", (0, 0))
        message = str(exc).split(":")[0]
        raise reader.error(f"line {line}", f"malformed XML: {message} (column {column + 1})"
                           "; is it a URDF file?") from None
    except RecursionError:
        raise reader.error("", "the XML is nested too deeply to read") from None
    return read_robot(reader, root)


def read_robot(reader, root):
    """The ``Robot`` of the parsed XML ``root`` (a ``<robot>``)."""
    if _tag(root) != "robot" or "}" in str(root.tag):
        raise reader.error("", f"the top element is <{_tag(root)}>, not <robot>; is it a "
                           "URDF file?")
    name = root.get("name", "").strip() or "robot"
    links, joints, transmissions = {}, {}, []
    for element in root.findall("material"):     # named colours the visuals may use
        colour = reader.colour(element, f"material {element.get('name', '')!r}")
        if colour:
            reader.materials[element.get("name", "").strip()] = colour
    for element in root:
        tag = _tag(element)
        if "}" in str(element.tag) and "xacro" in str(element.tag):
            raise reader.error(f"<{tag}>", "is a xacro macro: expand the file first "
                               "(xacro robot.urdf.xacro > robot.urdf)")
        if element.tag == "link":
            link = reader.link(element)
            if link.name in links:
                raise reader.error(f"link {link.name!r}", "is defined twice; link names "
                                   "must be unique")
            links[link.name] = link
        elif element.tag == "joint":
            joint = reader.joint(element)
            if joint.name in joints:
                raise reader.error(f"joint {joint.name!r}", "is defined twice; joint names "
                                   "must be unique")
            joints[joint.name] = joint
        elif element.tag == "material":
            pass
        elif element.tag == "transmission":
            transmissions.append(reader.transmission(element))
            reader.skip("transmission")
        elif isinstance(element.tag, str):
            reader.skip(tag)
    if not links:
        raise reader.error("", "holds no <link>; a robot needs at least one")
    return Robot(name, links, joints, transmissions, reader.not_used)
