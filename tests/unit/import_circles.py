"""Import circles among the modules of the rosmc_* packages, and a finder for them.

Used by ``test_import_circles.py``. Every import counts, wherever it is written: at the top,
inside a function (a "lazy" import) or under ``TYPE_CHECKING``. Each one ties the two
modules together (a change to one can break the other, neither can be read or tested
alone), so hiding a circle in a function or a type-only import does not take it away; a
:class:`typing.Protocol` of what one side needs does (see ``rosmc_server/ros/server_host.py``).

``from package import name`` counts as an import of the module ``package.name`` when there
is one, else of the package (its ``__init__.py``); the package a module lives in is not
counted (Python imports it first anyway, and ``from . import sibling`` means the sibling).
"""

from __future__ import annotations

import ast
from pathlib import Path

from tests.unit.layering_rules import REPO, absolute_module, module_path, package_modules


def imported_modules(path: Path, root: Path = REPO) -> set[str]:
    """The rosmc_* modules (paths below ``root``) that the module at ``path`` imports."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = absolute_module(node, path, root)
            for alias in node.names:
                submodule = f"{base}.{alias.name}"
                is_module = module_path(submodule, root) != module_path(base, root)
                names.append(submodule if is_module else base)
    found = {module_path(name, root) for name in names if name.startswith("rosmc_")}
    found.discard(path.relative_to(root).as_posix())
    return {name for name in found if (root / name).is_file()}


def import_graph(root: Path = REPO) -> dict[str, set[str]]:
    """Module -> the modules it imports, for every module of the rosmc_* packages."""
    return {
        path.relative_to(root).as_posix(): imported_modules(path, root)
        for path in package_modules(root)
    }


def import_circles(root: Path = REPO) -> list[frozenset[str]]:
    """Every group of modules that import each other, directly or through others.

    The strongly connected components of :func:`import_graph` with more than one module
    (Tarjan's algorithm, iterative so that a long chain cannot exhaust the stack).
    """
    graph = import_graph(root)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[frozenset[str]] = []
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, edges = work[-1]
            target = next(edges, None)
            if target is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    members = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        members.add(member)
                        if member == node:
                            break
                    if len(members) > 1:
                        circles.append(frozenset(members))
            elif target not in index:
                index[target] = low[target] = len(index)
                stack.append(target)
                on_stack.add(target)
                work.append((target, iter(sorted(graph[target]))))
            elif target in on_stack:
                low[node] = min(low[node], index[target])
    return circles
