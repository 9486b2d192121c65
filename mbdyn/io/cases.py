"""Cases and overrides merged into a model file's document, each value remembering where it
was written (``cases.a.initial.theta``, ``--set ...``) so that an error points there:
``apply_case`` merges a ``[cases.NAME]`` table, ``apply_override`` sets one dotted key
path (``split_path``).  Cases and overrides change parameters; they cannot declare new ones.
"""
from __future__ import annotations

import copy
import re

from .errors import ModelFileError
from .keys import SECTIONS
from .wording import format_path, suggest


def _element_index(items, name):
    for i, item in enumerate(items):
        if isinstance(item, dict) and item.get("name") == name:
            return i
    return None


def apply_case(doc, case_name, checker):
    """The document with case ``case_name`` merged in (``doc`` is not modified)."""
    cases = doc.get("cases", {})
    if case_name not in cases:
        known = ", ".join(cases) or "(this file defines no cases)"
        raise checker.error(("cases",), f"no case {case_name!r}; {suggest(case_name, cases)}"
                            f"the cases are: {known}")
    out = copy.deepcopy({k: v for k, v in doc.items() if k != "cases"})
    prefix = f"cases.{case_name}"
    for key, value in cases[case_name].items():
        layout = SECTIONS[key][0]
        if layout == "array":
            base = out.setdefault(key, [])
            if isinstance(value, list):
                out[key] = copy.deepcopy(value)
                checker.origins[(key,)] = f"{prefix}.{key}"
                continue
            for name, partial in value.items():
                idx = _element_index(base, name)
                if idx is None:
                    base.append({"name": name})
                    idx = len(base) - 1
                    checker.origins[(key, idx)] = f"{prefix}.{key}.{name}"
                for k, v in partial.items():
                    base[idx][k] = copy.deepcopy(v)
                    checker.origins[(key, idx, k)] = f"{prefix}.{key}.{name}.{k}"
        else:
            if key == "parameters":
                known_parameters(out, value, checker, lambda k: f"{prefix}.parameters.{k}")
            if key == "effects":
                _drop_switches(out.setdefault(key, {}), value)
            _merge_table(out.setdefault(key, {}), value, (key,), f"{prefix}.{key}", checker)
    return out


def _drop_switches(base, over):
    """Remove from the file's ``[effects]`` the names a case's ``[effects]`` switches: the
    case decides them (it may switch on what the file switches off), and one merged table
    never says both (``mbdyn.effects`` refuses a table that does)."""
    def listed(value):                  # the shapes are checked later, with the merge
        return [value] if isinstance(value, str) else \
            [n for n in value if isinstance(n, str)] if isinstance(value, list) else []
    names = set()
    for key, value in over.items():
        names.update(listed(value) if key in ("on", "off") else [key])
    for key in list(base):
        if key in ("on", "off") and isinstance(base[key], (str, list)):
            base[key] = [n for n in listed(base[key]) if n not in names]
        elif key in names:
            del base[key]


def known_parameters(doc, names, checker, where):
    """Cases and overrides change parameters; they cannot declare new ones (a typo must
    not pass silently)."""
    declared = doc.get("parameters", {})
    for k in names:
        if k not in declared:
            raise ModelFileError(checker.file, where(k), f"{k!r} is not a parameter of the "
                                 f"model; {suggest(k, declared)}the parameters are: "
                                 f"{', '.join(declared) or '(none)'} -- declare new ones in "
                                 "[parameters]")


def _merge_table(base, over, path, prefix, checker):
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(base.get(k), dict):
            _merge_table(base[k], v, path + (k,), f"{prefix}.{k}", checker)
        else:
            base[k] = copy.deepcopy(v)
            checker.origins[path + (k,)] = f"{prefix}.{k}"


_SEGMENT = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def split_path(text):
    """``"bodies[0].mass"`` / ``"bodies.0.mass"`` / ``"bodies.disk.mass"`` -> segments."""
    text = text.strip()
    if not text or text.startswith(".") or text.endswith(".") or ".." in text:
        raise ValueError(f"{text!r} is not a dotted key path such as parameters.b or "
                         "bodies.disk.mass")
    parts = []
    pos = 0
    for m in _SEGMENT.finditer(text):
        between = text[pos:m.start()]
        if between not in ("", "."):
            raise ValueError(f"{text!r} is not a dotted key path")
        parts.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if pos != len(text):
        raise ValueError(f"{text!r} is not a dotted key path")
    return [int(p) if isinstance(p, str) and p.isdigit() else p for p in parts]


def apply_override(doc, path_text, value, checker, origin):
    """Set the value at dotted ``path_text`` in ``doc`` (in place)."""
    parts = _override_parts(doc, path_text, checker, origin)
    node = doc
    path = []
    for depth, part in enumerate(parts):
        key = _key_of(node, part, path, checker, origin)
        path.append(key)
        if depth == len(parts) - 1:
            _set_value(node, key, value, path, checker, origin)
            return
        if isinstance(node, dict) and key not in node:
            nxt = parts[depth + 1]
            if depth == 0 and SECTIONS[key][0] == "array":
                raise ModelFileError(checker.file, origin, f"the file has no [[{key}]]; "
                                     "there is nothing to override")
            node[key] = {} if not isinstance(nxt, int) else []
        node = node[key]


def _override_parts(doc, path_text, checker, origin):
    """The segments of an override's key path: a section other than the cases, and a
    parameter the file declares."""
    try:
        parts = split_path(path_text)
    except ValueError as exc:
        raise ModelFileError(checker.file, origin, str(exc)) from None
    if parts[0] == "cases":
        raise ModelFileError(checker.file, origin, "cannot override cases; choose one with "
                             "--case and override its values by their normal paths")
    if parts[0] not in SECTIONS:
        raise ModelFileError(checker.file, origin, f"unknown section {parts[0]!r}; "
                             f"{suggest(parts[0], SECTIONS)}the sections are: "
                             + ", ".join(k for k in SECTIONS if k != "cases"))
    if parts[0] == "parameters" and len(parts) == 2:
        known_parameters(doc, [parts[1]], checker, lambda k: origin)
    return parts


def _key_of(node, part, path, checker, origin):
    """The key (or index) of ``part`` in ``node``, which ``path`` names: an index or an
    element's name in an array, a key in a table."""
    if isinstance(node, list):
        if isinstance(part, int):
            if not 0 <= part < len(node):
                raise ModelFileError(checker.file, origin, f"{format_path(path)} has "
                                     f"{len(node)} entries; index {part} does not exist")
            return part
        idx = _element_index(node, part)
        if idx is None:
            names = ", ".join(str(x.get("name")) for x in node if isinstance(x, dict))
            raise ModelFileError(checker.file, origin, f"{format_path(path)} has no "
                                 f"entry named {part!r}; {suggest(part, names.split(', '))}"
                                 f"the names are: {names or '(none)'}")
        return idx
    if isinstance(node, dict):
        if isinstance(part, int):
            raise ModelFileError(checker.file, origin, f"{format_path(path) or 'the file'} "
                                 f"is a table; [{part}] does not apply")
        return part
    raise ModelFileError(checker.file, origin, f"{format_path(path)} is a value, not a "
                         "table; shorten the path")


def _set_value(node, key, value, path, checker, origin):
    """``node[key] = value``, unless it would replace a table or an array of tables by a
    value; the origin is remembered at ``path``."""
    existing = node[key] if (isinstance(node, list) or key in node) else None
    if isinstance(existing, dict) and not isinstance(value, dict):
        raise ModelFileError(checker.file, origin, f"{format_path(path)} is a table; "
                             f"set one of its keys ({', '.join(existing)})")
    if (isinstance(existing, list) and existing
            and all(isinstance(x, dict) for x in existing)
            and not isinstance(value, list)):
        raise ModelFileError(checker.file, origin, f"{format_path(path)} is an array "
                             f"of tables; set a key of one entry, e.g. "
                             f"{format_path(path)}[0].name")
    node[key] = value
    checker.origins[tuple(path)] = origin
