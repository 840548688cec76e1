"""The folders of both tracks are layers along the data flow, and each uses
only those below it: no include (cpp/) or import (python_prototype/) of a
folder above, and no cycle among modules. The order is read from its one
place, the line of docs/layout.md that starts with "Layers:".

A module is cpp/FOLDER/NAME.h and .cpp together, or
python_prototype/FOLDER/NAME.py; the entry points (cpp/main.cpp, __main__.py)
and the run (simulation) are the top layers. The headers FFCx generates from
forms/ (biot_*.h) and Python's `import biot` are the layer `forms`, below
all. Includes of system and library headers (<...>) and imports of other
packages are not the project's and are not checked. Python imports are read
with `ast`, at any depth (a function-level import is an edge too)."""
import ast
import os
import re
import sys

from support import ROOT, check

ENTRY = {"main": "main", "__main__": "main"}


def layer_order():
    """The layers, lowest first, from docs/layout.md's "Layers:" line."""
    with open(os.path.join(ROOT, "docs", "layout.md")) as f:
        for line in f:
            if line.startswith("Layers:"):
                return [name.strip(" `.\n") for name in line[len("Layers:"):].split("->")]
    sys.exit("FAIL: docs/layout.md has no line starting with 'Layers:'")


def layer_of(module):
    """'contact/contact' -> 'contact'; 'simulation' -> 'simulation'; 'main'."""
    return module.split("/")[0] if "/" in module else ENTRY.get(module, module)


def cpp_edges(top):
    """(module, included module) for every quoted include under cpp/."""
    edges = set()
    for folder, _, files in os.walk(top):
        for f in files:
            stem, suffix = os.path.splitext(f)
            if suffix not in (".h", ".cpp"):
                continue
            source = os.path.relpath(os.path.join(folder, stem), top)
            with open(os.path.join(folder, f)) as text:
                for target in re.findall(r'^\s*#\s*include\s+"([^"]+)"', text.read(), re.M):
                    if re.fullmatch(r"biot_\w+\.h", target):
                        edges.add((source, "forms"))
                    else:
                        edges.add((source, os.path.splitext(target)[0]))
    return edges


def python_target(source, node):
    """The prototype module an import names, or None for another package."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
        return ["forms" if n == "biot" else n.replace(".", "/")[len("python_prototype/"):]
                for n in names if n == "biot" or n.startswith("python_prototype.")]
    if node.level == 0:
        if node.module and node.module.startswith("python_prototype."):
            return [node.module[len("python_prototype."):].replace(".", "/")]
        return []
    package = source.split("/")[:-1]
    base = package[:len(package) - (node.level - 1)] if node.level > 1 else package
    module = base + (node.module.split(".") if node.module else [])
    if node.module is None:  # "from . import x": x is a module of the package
        return ["/".join(base + [a.name]) for a in node.names]
    return ["/".join(module)]


def python_edges(top):
    edges = set()
    for folder, _, files in os.walk(top):
        for f in files:
            stem, suffix = os.path.splitext(f)
            if suffix != ".py" or stem == "__init__":
                continue
            source = os.path.relpath(os.path.join(folder, stem), top)
            with open(os.path.join(folder, f)) as text:
                tree = ast.parse(text.read())
            for node in ast.walk(tree):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    edges.update((source, t) for t in python_target(source, node) if t != source)
    return edges


def upward(edges, order):
    """The edges whose target lies in a layer above the source's."""
    rank = {name: i for i, name in enumerate(order)}
    unknown = sorted({layer_of(m) for e in edges for m in e} - set(rank))
    check(not unknown, f"every folder is a layer of docs/layout.md (not: {unknown})")
    return sorted((s, t) for s, t in edges if rank[layer_of(t)] > rank[layer_of(s)])


def cycle(edges):
    """One cycle among modules (a list of modules), or None."""
    graph = {}
    for s, t in edges:
        if s != t:
            graph.setdefault(s, set()).add(t)
    state = {}

    def visit(node, path):
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return path[path.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt, path + [nxt])
                if found:
                    return found
        state[node] = "done"
        return None

    for start in sorted(graph):
        if start not in state:
            found = visit(start, [start])
            if found:
                return found
    return None


def main():
    order = layer_order()
    check(len(order) == len(set(order)) and len(order) >= 10, f"docs/layout.md lists the layers once each: {order}")
    for track, edges in (("cpp", cpp_edges(os.path.join(ROOT, "cpp"))),
                         ("python_prototype", python_edges(os.path.join(ROOT, "python_prototype")))):
        up = upward(edges, order)
        check(not up, f"{track}: no module uses a layer above its own ({len(edges)} edges; upward: "
                      + "; ".join(f"{s} -> {t}" for s, t in up) + ")")
        loop = cycle(edges)
        check(loop is None, f"{track}: no cycle among modules ({' -> '.join(loop or [])})")


main()
