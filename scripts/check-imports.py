#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""The Python package's imports point one way (docs/layout.md, "Layers"): each module imports only
from its own layer or the layers below it, and no modules import each other round a cycle. Every
import counts, those inside functions too (an import put off until a call still runs upward);
only those under `if TYPE_CHECKING:` are left out, as they never run.

    scripts/check-imports.py [PACKAGE_DIR]     (default python/sediment; exit 1 on a breach)
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

# Lowest first. A module's layer is that of the longest prefix of its name listed here.
LAYERS = (
    ("base", ("sediment.constants", "sediment._core", "sediment.plausible", "sediment.csvfile", "sediment.results",
              "sediment.progress", "sediment.figures", "sediment.folders")),
    ("lab", ("sediment.lab",)),
    ("sim", ("sediment.sim",)),
    ("planner", ("sediment.planner",)),
    ("studies", ("sediment.studies",)),
    ("inverse", ("sediment.inverse",)),
    ("cli", ("sediment.cli", "sediment.__main__")),
    ("package", ("sediment",)),    # the package's own names (sediment.lammps_with_styles, ...), loaded on use
)


def layer_of(module: str) -> int:
    """The index in LAYERS of a module's layer."""
    best, rank = -1, -1
    for index, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            if (module == prefix or module.startswith(prefix + ".")) and len(prefix) > best:
                best, rank = len(prefix), index
    if rank < 0:
        raise SystemExit(f"check-imports: {module} is in no layer: add it to LAYERS in {__file__}")
    return rank


def modules(root: Path) -> dict[str, Path]:
    """Every module of the package by its dotted name (a package by its __init__)."""
    found = {}
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root.parent).with_suffix("").parts
        if "examples" in parts:    # a link to the repository's examples/, not the package
            continue
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    found[f"{root.name}._core"] = root / "_core.pyi"    # the compiled core: imports nothing of the package
    return found


def _type_checking(node: ast.If) -> bool:
    test = node.test
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or \
        (isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def imports(name: str, path: Path, known: dict[str, Path]) -> list[tuple[int, str]]:
    """(line, module) of each import of the package's modules in one module."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    top = name.split(".")[0]
    out = []

    def visit(node: ast.AST) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _type_checking(child):
                for other in child.orelse:
                    visit(other)
                continue
            if isinstance(child, ast.Import):
                out.extend((child.lineno, a.name) for a in child.names if a.name.split(".")[0] == top)
            elif isinstance(child, ast.ImportFrom):
                base = child.module or ""
                if child.level:
                    anchor = package.split(".")[:len(package.split(".")) - (child.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                if base.split(".")[0] != top:
                    continue
                for alias in child.names:    # `from .. import _core` imports the module sediment._core
                    sub = f"{base}.{alias.name}"
                    out.append((child.lineno, sub if sub in known else base))
            visit(child)
    visit(ast.parse(path.read_text(), str(path)))
    return out


def check(root: Path) -> list[str]:
    """The breaches: imports upward, and cycles."""
    known = modules(root)
    graph: dict[str, set[str]] = {name: set() for name in known}
    problems = []
    for name, path in known.items():
        if path.suffix != ".py":
            continue
        for line, target in imports(name, path, known):
            if target not in known:
                continue
            here, there = layer_of(name), layer_of(target)
            if there > here:
                problems.append(f"{path}:{line}: {name} ({LAYERS[here][0]}) imports {target} ({LAYERS[there][0]}), "
                                "a layer above it")
            if target != name:
                graph[name].add(target)
    problems += [f"import cycle: {' -> '.join(cycle)}" for cycle in cycles(graph)]
    return problems


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """One cycle through each strongly connected group of modules (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    groups = []

    def connect(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(set(group))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            connect(v)
    return [_path_round(group, graph) for group in groups]


def _path_round(group: set[str], graph: dict[str, set[str]]) -> list[str]:
    """A cycle within a strongly connected group, from its first module back to it."""
    start = min(group)
    seen, path = {start}, [start]
    while True:
        step = min(w for w in graph[path[-1]] if w in group)
        if step in seen:
            return path[path.index(step):] + [step]
        seen.add(step)
        path.append(step)


def main() -> int:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "python" / "sediment")
    problems = check(root)
    for problem in problems:
        print(problem)
    if problems:
        print(f"check-imports: {len(problems)} import(s) against the layers (lowest first: "
              f"{', '.join(name for name, _ in LAYERS)}); docs/layout.md says what each may import")
        return 1
    print(f"check-imports: {len(modules(root))} modules, imports point one way, no cycles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
