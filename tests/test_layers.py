"""The package's imports follow its layers (docs/architecture.md): no module imports one of a
higher layer, except the few lazy imports listed here with their reason, and no two
modules import each other, directly or round a circle.  Every import counts, also those
inside functions.  The layers are written once, here; docs/architecture.md shows them."""
from __future__ import annotations

import ast
import os
from pathlib import Path

import networkx as nx

PACKAGE = Path(__file__).resolve().parent.parent / "mbdyn"

#: bottom to top: a module may import from its own layer and the layers below
LAYERS = [
    # the package itself imports its public names on first use only (PEP 562)
    ("ground", ["mbdyn.errors", "mbdyn.limits", "mbdyn.names", "mbdyn.escape", "mbdyn.files"]),
    ("kernels", ["mbdyn.kernels"]),
    # flexible bodies' beam model, reductions and inertia invariants (numpy, scipy only);
    # the element records and the packing at compile build on them
    ("flexible", ["mbdyn.flexible"]),
    ("elements", ["mbdyn.elements"]),
    ("algorithms", ["mbdyn.algorithms"]),
    ("compiled", ["mbdyn.compiled"]),
    ("assembly", ["mbdyn.assembly"]),
    ("symbolic", ["mbdyn.symbolic"]),
    ("integrate", ["mbdyn.integrate"]),
    ("analysis", ["mbdyn.analysis"]),
    ("io", ["mbdyn.io"]),
    ("viz", ["mbdyn.viz"]),
    ("cli", ["mbdyn.cli", "mbdyn.__main__"]),
]

#: the upward imports the design allows, each lazy (inside a function) and why
LAZY_UPWARD = {
    # Result.plot / Result.animate: thin methods, matplotlib loads on call
    ("mbdyn.integrate.result", "mbdyn.viz"),
    # a sweep member is a model file: its worker reads it with the loader
    ("mbdyn.analysis.sweeps.model_file", "mbdyn.io.loader"),
    ("mbdyn.analysis.sweeps.grid", "mbdyn.io.schema"),
}


def _module_name(path):
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path, name):
    """``{imported module: lazy?}`` of one module (mbdyn's modules only)."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    top_level = {id(n) for n in tree.body}
    for node in tree.body:          # imports under a top-level if/try are not lazy
        if isinstance(node, (ast.If, ast.Try)):
            top_level |= {id(n) for n in ast.walk(node)}
    out = {}
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            targets = [f"{module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        for target in targets:
            if target.startswith("mbdyn."):
                out.setdefault(target, True)
                out[target] &= id(node) not in top_level
    return out


def _graph():
    modules = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph = nx.DiGraph()
    for name, path in modules.items():
        graph.add_node(name)
        for target, lazy in _imports(path, name).items():
            while target not in modules and "." in target:   # a name inside a module
                target = target.rsplit(".", 1)[0]
            if target in modules and target != name and not name.startswith(target + "."):
                graph.add_edge(name, target, lazy=lazy)
    return graph


def layer_of(module):
    if module == "mbdyn":
        return 0
    for rank, (_, prefixes) in enumerate(LAYERS):
        if any(module == p or module.startswith(p + ".") for p in prefixes):
            return rank
    return None


def test_every_module_has_a_layer():
    assert [m for m in _graph() if m != "mbdyn" and layer_of(m) is None] == []


def test_no_import_runs_up_the_layers():
    graph = _graph()
    upward = []
    for a, b, data in graph.edges(data=True):
        if a == "mbdyn" or layer_of(a) >= layer_of(b):
            continue
        allowed = any(a == x and (b == y or b.startswith(y + ".")) for x, y in LAZY_UPWARD)
        if not (allowed and data["lazy"]):
            upward.append(f"{a} ({LAYERS[layer_of(a)][0]}) -> {b} ({LAYERS[layer_of(b)][0]})")
    assert upward == []


def test_no_import_circles():
    cycles = [c for c in nx.strongly_connected_components(_graph()) if len(c) > 1]
    assert cycles == []


def test_the_allowed_upward_imports_still_exist():
    """An entry of LAZY_UPWARD that the code no longer needs is removed from the list."""
    graph = _graph()
    for a, b in LAZY_UPWARD:
        assert any(x == a and (y == b or y.startswith(b + ".")) for x, y in graph.edges), (a, b)


def test_modules_and_functions_stay_small():
    """No module over 400 lines and no function over 60 lines of code (its docstring not
    counted) without a reason written at its top (a comment line starting ``# long:``
    right after the docstring)."""
    long_modules, long_functions = [], []
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text()
        lines = text.splitlines()
        where = str(path.relative_to(PACKAGE.parent))
        if len(lines) > 400 and not any(ln.startswith("# long:") for ln in lines[:40]):
            long_modules.append(f"{where}: {len(lines)}")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = node.body[0]
                start = first.end_lineno if (isinstance(first, ast.Expr) and isinstance(
                    getattr(first, "value", None), ast.Constant)) else node.lineno
                size = node.end_lineno - start
                head = lines[node.lineno:start + 3]
                if size > 60 and not any(ln.strip().startswith("# long:") for ln in head):
                    long_functions.append(f"{where}:{node.name} ({size} lines)")
    assert long_modules == [] and long_functions == []


if __name__ == "__main__":      # print the graph's upward edges and the long places
    for a, b, d in _graph().edges(data=True):
        if a != "mbdyn" and layer_of(a) < layer_of(b):
            print("up", a, "->", b, "lazy" if d["lazy"] else "")
    print(os.linesep.join(map(str, nx.simple_cycles(_graph()))))


def test_every_relative_import_names_a_module_that_exists():
    """Lazy imports run only when called: one left pointing at a moved module would fail
    only in the user's hands."""
    graph_modules = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    # C extensions (setup.py) by their sources: mbdyn/kernels/_fastcall.c
    extensions = {".".join(p.relative_to(PACKAGE.parent).with_suffix("").parts)
                  for p in PACKAGE.rglob("*.c")}
    missing = []
    for name, path in graph_modules.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
                if module not in graph_modules and module not in extensions:
                    missing.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {module}")
    assert missing == []
