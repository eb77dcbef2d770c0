"""The node-parameter part of docs/reference.md, read from the nodes' own modules.

For each node in :data:`NODES`, every private parameter its modules read with
``rospy.get_param("~name", default)`` (found with ``ast``, names held in module constants
included), its default when that is a literal, and what the node module's docstring says of
it. Used by ``tools/gen_msg_reference.py``; nothing here imports the modules it reads.
"""

from __future__ import annotations

import ast
import json
import re
from dataclasses import dataclass
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
STATION = "rosmc_server/common/ros/station.py"

# (node name, its module, more modules it reads parameters through: path -> the names it
# reads there, None for all). The node module's docstring describes every parameter.
NODES: tuple[tuple[str, str, dict[str, tuple[str, ...] | None]], ...] = (
    (
        "/rosmc/mission_server",
        "rosmc_server/ros/server_node.py",
        {"rosmc_server/ros/server_config.py": None, STATION: ("~cwd", "~station_journal")},
    ),
    (
        "/<robot>/mission_executor",
        "rosmc_server/executor/ros/node.py",
        {"rosmc_server/executor/ros/config.py": None, STATION: ("~cwd",)},
    ),
    ("/rosmc/sim", "rosmc_sim/ros/sim_node.py", {STATION: ("~cwd",)}),
    (
        "/rosmc/markers",
        "rosmc_rviz_markers/ros/node.py",
        {"rosmc_rviz_markers/ros/config.py": None},
    ),
    ("/rosmc/link_emulator", "rosmc_sim/ros/link_emulator.py", {}),
    ("/rosmc/demo_operator", "rosmc_sim/ros/demo_operator.py", {STATION: ("~cwd",)}),
)


@dataclass(frozen=True)
class Parameter:
    """One private parameter of a node."""

    name: str  # with its "~"
    default: str  # the literal default as text, "" when it is computed
    description: str


def _string_constants(tree: ast.Module) -> dict[str, str]:
    """Module-level ``NAME = "text"`` assignments."""
    found: dict[str, str] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
            for target in node.targets:
                if isinstance(target, ast.Name) and isinstance(node.value.value, str):
                    found[target.id] = node.value.value
    return found


def _constants_around(path: Path) -> dict[str, str]:
    """String constants of the module and of every ``topics.py`` of its package and parent."""
    constants: dict[str, str] = {}
    for topics in (path.parent / "topics.py", path.parent.parent / "topics.py"):
        if topics.exists():
            constants.update(_string_constants(ast.parse(topics.read_text())))
    constants.update(_string_constants(ast.parse(path.read_text())))
    return constants


def _text(node: ast.expr, constants: dict[str, str]) -> str | None:
    """The string an expression names: a literal, a constant, or a sum of those."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.Name):
        return constants.get(node.id)
    if isinstance(node, ast.Attribute):
        return constants.get(node.attr)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _text(node.left, constants), _text(node.right, constants)
        return None if left is None or right is None else left + right
    return None


def read_params(path: Path) -> dict[str, str]:
    """Every ``get_param("~name", default)`` of a module: name -> literal default ("" if none)."""
    constants = _constants_around(path)
    found: dict[str, str] = {}
    for node in ast.walk(ast.parse(path.read_text())):
        if not (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "get_param"
            and node.args
        ):
            continue
        name = _text(node.args[0], constants)
        if name is None or not name.startswith("~"):
            continue
        default = ""
        if len(node.args) > 1:
            try:
                default = json.dumps(ast.literal_eval(node.args[1]))
            except ValueError:
                default = ""
        found.setdefault(name, default)
    return found


def describe(docstring: str, name: str, names: set[str]) -> str:
    """What ``docstring`` says of parameter ``name``: from its defining mention to the next.

    A defining mention is the first ````~x```` followed by `` (`` or ``:``; the description
    runs to the next parameter's defining mention or the end of the paragraph.
    """
    starts = {}
    for other in names:
        match = re.search(rf"``{re.escape(other)}``(?=\s*[(:])", docstring)
        if match:
            starts[other] = match
    if name not in starts:
        return ""
    begin = starts[name].end()
    end = min(
        [m.start() for other, m in starts.items() if m.start() > begin]
        + [_paragraph_end(docstring, begin)]
    )
    text = " ".join(docstring[begin:end].split())
    text = re.sub(r":\w+:`~?\.*([^`]*)`", r"`\1`", text).replace("``", "`")
    return text.strip().removeprefix(":").strip().rstrip(",;.").strip()


def _paragraph_end(text: str, start: int) -> int:
    found = text.find("\n\n", start)
    return len(text) if found < 0 else found


def node_parameters(root: Path = REPO_ROOT) -> list[tuple[str, str, list[Parameter]]]:
    """(node, module, parameters sorted by name) for every node of :data:`NODES`."""
    nodes = []
    for node, module, more in NODES:
        path = root / module
        params = read_params(path)
        for other, wanted in more.items():
            found = read_params(root / other)
            params.update({k: v for k, v in found.items() if wanted is None or k in wanted})
        docstring = ast.get_docstring(ast.parse(path.read_text())) or ""
        rows = [
            Parameter(name, default, describe(docstring, name, set(params)))
            for name, default in sorted(params.items())
        ]
        nodes.append((node, module, rows))
    return nodes


def render(root: Path = REPO_ROOT) -> list[str]:
    """Markdown lines: one table per node."""
    out = ["## Node parameters", ""]
    out += [
        "Private parameters (`_name:=value` with rosrun, or a launch file's `<param>`), as each",
        "node's module reads them; the default is given where the code names a literal.",
        "",
    ]
    for node, module, params in node_parameters(root):
        out += [f"### `{node}`", "", f"Read in `{module}`.", ""]
        out += ["| Parameter | Default | Meaning |", "| --- | --- | --- |"]
        for param in params:
            default = f"`{param.default}`" if param.default else ""
            meaning = param.description.replace("|", "\\|")
            out.append(f"| `{param.name}` | {default} | {meaning} |")
        out.append("")
    return out
