"""The import rules of the layers, and a scanner that finds where a module breaks them.

Used by ``test_layering.py``. Layering: who may import what, on every module of the
``rosmc_*`` packages.

DESIGN §2 and the issue that split the conversions out: the packages form one
order of layers, and a module imports only from its own layer or below::

    core < conversions < recording < ros < client < app
    (0)(1)(2)(3)(4)(5)

* **core**: every ``core/`` package of every component, whatever its depth (a folder named
  ``core`` is the core layer without a table entry: ``rosmc_server/core``,
  ``rosmc_server/executor/core``, ``rosmc_sim/core``, ``rosmc_rviz_markers/core``, and a
  command-GUI ``core/`` once there is one), ``rosmc_server/interface.py`` (graph names),
  ``rosmc_server/text`` (plain-text rendering of core objects) and the executor's plain
  skills. Pure Python.
* **conversions**: ``rosmc_server/conversions`` (the only msg <-> core boundary; generated
  messages and genpy, no rospy).
* **recording**: ``rosmc_server/recording`` (the MCAP journal, history, timelines).
* **ros**: the ROS adapters of the server, the replayer, the executor and the simulator
  (``rosmc_server/ros``, ``rosmc_server/executor/ros``, ``rosmc_sim/ros``).
* **client**: ``rosmc_server/ros/client``.
* **app**: the CLI (``rosmc_server/cli``), the GUIs (everything of ``rosmc_rviz_markers``
  and ``rosmc_rqt_command`` outside their ``core/``), the demos and the scripted demo
  operator (``rosmc_sim/ros/demo_operator.py``).

Besides the order, by what a module imports from outside:

* **ROS runtime** (rospy, rosgraph, interactive_markers, tf2_ros, ...) only in a *ROS
  adapter module*: one inside a ``ros/`` package, or named ``ros_*.py`` or ``node.py``;
  and in a GUI's *entry modules* (``plugin.py``, the rqt Plugin, and ``standalone.py``,
  the window's ``main``: they make the node and build the bridge and the widgets). So the
  command GUI's Qt models and widgets never import rospy; its one adapter is
  ``rosmc_rqt_command/ros_bridge.py``, and the marker servers' rospy lives in
  ``rosmc_rviz_markers/ros/``.
* **Messages** (genpy, ``rosmc.msg``/``rosmc.srv``, std/geometry/visualization messages,
  rosbag) only in conversions, recording and ROS adapter modules: never in a core, the
  text rendering, the CLI or a GUI model/widget (they get core objects from the client).
* **Qt** only in the GUI packages outside their ``core/``.
* **pybullet** only in ``rosmc_sim/core``.
* **The executor is the robot's**: the ground (``rosmc_server`` outside its ``executor/``)
  imports nothing of it; what both ends speak (the robot link's protocol) is in
  ``rosmc_server/core``. A robot may run without the ground's code and the other way round.
* **The packages in order** (:data:`PACKAGE_RANK`): ``rosmc_server`` < ``rosmc_sim`` <
  the GUIs. The server imports no GUI and no simulator (drawing primitives are in
  ``rosmc_server/core/views/geometry.py``), the simulator no GUI.
* **The executor imports nothing of the ground's own modules** (:data:`GROUND_ONLY`): the
  ROS helpers both ends run (radio, station, logging bridge) are ``rosmc_server/common``.
* **The server's insides**: apps reach the graph through the client. They import nothing
  of ``rosmc_server.ros`` but the client and the replayer (their ROS adapters may use
  ``rosmc_server.common.ros``); a GUI
  model or widget (neither a ROS adapter nor an entry module) imports nothing of
  ``rosmc_server.ros`` at all: the bridge hands it core objects.

The scanner reads every module with :mod:`ast`, so a forbidden import is found even where
it would never run (inside a function, an ``if`` or ``TYPE_CHECKING``). One exception: a GUI
module may name the client's types under ``if TYPE_CHECKING:`` (nothing loads the client;
mypy then checks each request a widget makes against the client method's signature).
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PACKAGES = ("rosmc_server", "rosmc_sim", "rosmc_rviz_markers", "rosmc_rqt_command")

LAYERS = ("core", "conversions", "recording", "ros", "client", "app")
RANK = {name: rank for rank, name in enumerate(LAYERS)}

# Path (a folder ending in "/" or one file) -> layer; the longest matching entry wins, and a
# folder named "core" counts as an entry "<its path>/" of the core layer. A new folder or
# top-level module needs an entry (test_every_module_has_a_layer says so); every entry names
# a file or folder that exists (test_the_table_names_real_paths).
LAYER_OF_PATH = {
    "rosmc_server/__init__.py": "core",
    "rosmc_server/interface.py": "core",
    "rosmc_server/venv.py": "core",  # sys.path only: entry scripts call it before anything
    "rosmc_server/text/": "core",
    "rosmc_server/executor/__init__.py": "core",
    "rosmc_server/executor/basic_skills.py": "core",
    "rosmc_server/conversions/": "conversions",
    "rosmc_server/recording/": "recording",
    "rosmc_server/ros/": "ros",
    "rosmc_server/common/": "ros",  # ROS helpers of every node, ground or robot
    "rosmc_server/executor/ros/": "ros",
    "rosmc_server/ros/client/": "client",
    "rosmc_server/cli/": "app",
    "rosmc_server/demo.py": "app",
    "rosmc_sim/__init__.py": "core",
    "rosmc_sim/ros/": "ros",
    "rosmc_sim/ros/demo_operator.py": "app",
    "rosmc_sim/demo.py": "app",
    "rosmc_rviz_markers/": "app",
    "rosmc_rqt_command/": "app",
}
CORE_FOLDER = "core"

ROS_RUNTIME = {
    "rospy",
    "rosgraph",
    "roslaunch",
    "rosnode",
    "rosservice",
    "rostopic",
    "rosparam",
    "interactive_markers",
    "tf2_ros",
    "tf",
    "actionlib",
}
MESSAGES = {
    "genpy",
    "roslib",
    "rosbag",
    "rosmc",
    "std_msgs",
    "std_srvs",
    "geometry_msgs",
    "visualization_msgs",
    "nav_msgs",
    "sensor_msgs",
    "tf2_msgs",
}
QT = {
    "PyQt5",
    "PyQt6",
    "PySide2",
    "PySide6",
    "python_qt_binding",
    "Qt",
    "qt_gui",
    "rqt_gui",
    "rqt_gui_py",
}
PYBULLET = {"pybullet", "pybullet_data"}
WHY = {
    **dict.fromkeys(ROS_RUNTIME, "the ROS runtime: only ROS adapter modules"),
    **dict.fromkeys(MESSAGES, "messages: only conversions, recording and ROS adapters"),
    **dict.fromkeys(QT, "Qt: only the GUI packages outside core/"),
    **dict.fromkeys(PYBULLET, "pybullet: only rosmc_sim/core"),
}
GUI_PACKAGES = ("rosmc_rviz_markers/", "rosmc_rqt_command/")
EXECUTOR = "rosmc_server/executor/"
PYBULLET_ALLOWED = ("rosmc_sim/core/",)
# What the apps may use of rosmc_server.ros: the client and what serves clients. (The
# shared helpers of rosmc_server.common.ros, logging to rosout and the station's paths
# among them, are any ROS adapter's; a GUI model or widget uses none of them.)
FOR_APPS = (
    "rosmc_server.ros.client",
    "rosmc_server.ros.replayer",
)
COMMON_ROS = "rosmc_server.common.ros"
# The packages in their order: a package imports only from its own rank or below (the
# GUIs draw with rosmc_server.core.views.geometry; the server never imports a GUI or the sim).
PACKAGE_RANK = {
    "rosmc_server": 0,
    "rosmc_sim": 1,
    "rosmc_rviz_markers": 2,
    "rosmc_rqt_command": 2,
}
# The ground's own modules: the executor (the robot's) imports none of them. It shares the
# core, the graph names, the message conversions and rosmc_server/common with the ground.
GROUND_ONLY = (
    "rosmc_server/ros/",
    "rosmc_server/recording/",
    "rosmc_server/cli/",
    "rosmc_server/text/",
    "rosmc_server/demo.py",
)
CONVERSIONS = "rosmc_server.conversions"
CLIENT = "rosmc_server.ros.client"  # a GUI module may name its types for the type checker
# Dynamic imports with a literal module name are checked too.
IMPORT_FUNCTIONS = {"import_module", "__import__"}


@dataclass(frozen=True)
class Violation:
    """One forbidden import."""

    path: str
    line: int
    module: str
    why: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line} imports {self.module} ({self.why})"


def package_modules(root: Path = REPO) -> list[Path]:
    """Every module of the repository's rosmc_* packages."""
    return sorted(
        path
        for package in PACKAGES
        for path in (root / package).glob("**/*.py")
        if "__pycache__" not in path.parts
    )


def core_modules(root: Path = REPO) -> list[Path]:
    """Every module of every ``core`` package of the repository's rosmc_* packages."""
    return sorted(
        path for path in root.glob("rosmc_*/**/core/**/*.py") if "__pycache__" not in path.parts
    )


def layer_of(relative: str) -> str | None:
    """The layer of a module given by its path below the repository (None: no entry)."""
    table = dict(LAYER_OF_PATH)
    folders = relative.split("/")[:-1]
    if CORE_FOLDER in folders[1:]:
        table["/".join(folders[: folders.index(CORE_FOLDER, 1) + 1]) + "/"] = "core"
    matches = [
        key for key in table if key == relative or (key.endswith("/") and relative.startswith(key))
    ]
    return table[max(matches, key=len)] if matches else None


def is_gui_entry(relative: str) -> bool:
    """A GUI package's ``plugin.py`` or ``standalone.py`` (they start the GUI)."""
    package, *rest = relative.split("/")
    return f"{package}/" in GUI_PACKAGES and rest in (["plugin.py"], ["standalone.py"])


def is_ros_adapter(relative: str) -> bool:
    """A module that may use the ROS runtime: in a ``ros/`` package, ``ros_*.py`` or ``node.py``."""
    *folders, name = relative.split("/")
    return "ros" in folders[1:] or name.startswith("ros_") or name == "node.py"


def module_name(path: Path, root: Path) -> list[str]:
    """The dotted module name of ``path`` (below ``root``), as its parts."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    return parts[:-1] if parts[-1] == "__init__" else parts


def absolute_module(node: ast.ImportFrom, path: Path, root: Path) -> str:
    """The absolute module an ``from ... import`` names (resolving leading dots)."""
    if node.level == 0:
        return node.module or ""
    package = module_name(path, root)
    if path.name != "__init__.py":
        package = package[:-1]
    base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
    return ".".join([*base, *([node.module] if node.module else [])])


def _imported(tree: ast.AST, path: Path, root: Path) -> list[tuple[int, str]]:
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            module = absolute_module(node, path, root)
            found.append((node.lineno, module))
            # "from rosmc_server import ros" imports the ros layer too.
            found += [(node.lineno, f"{module}.{alias.name}") for alias in node.names]
        elif isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in IMPORT_FUNCTIONS and node.args:
                first = node.args[0]
                if isinstance(first, ast.Constant) and isinstance(first.value, str):
                    found.append((node.lineno, first.value))
    return found


def module_path(module: str, root: Path) -> str:
    """The path of the file an imported ``rosmc_*`` name lives in (its longest module part)."""
    parts = module.split(".")
    for end in range(len(parts), 0, -1):
        stem = "/".join(parts[:end])
        if (root / f"{stem}.py").is_file():
            return f"{stem}.py"
        if (root / stem / "__init__.py").is_file():
            return f"{stem}/__init__.py"
    return "/".join(parts) + ".py"


def _outside_rule(relative: str, top: str) -> bool:
    """Whether ``relative`` may import the third-party module ``top``."""
    layer = layer_of(relative)
    gui = relative.startswith(GUI_PACKAGES)
    if top in ROS_RUNTIME:
        return is_ros_adapter(relative) or is_gui_entry(relative)
    if top in MESSAGES:
        if is_ros_adapter(relative):
            return True
        return layer in ("conversions", "recording")
    if top in QT:
        return gui and layer != "core"
    if top in PYBULLET:
        return relative.startswith(PYBULLET_ALLOWED)
    return True


def _inside_rule(relative: str, module: str, root: Path) -> str | None:
    """Why ``relative`` may not import the rosmc_* name ``module`` (None: it may)."""
    layer = layer_of(relative)
    target = module_path(module, root)
    target_layer = layer_of(target)
    if layer is None or target_layer is None:
        return None  # reported by the test that every module has a layer
    if RANK[target_layer] > RANK[layer]:
        return f"the {target_layer} layer, above this {layer} module"
    package, target_package = relative.split("/")[0], target.split("/")[0]
    if PACKAGE_RANK.get(target_package, 0) > PACKAGE_RANK.get(package, 0):
        return f"the package {target_package}, above {package}"
    ground = relative.startswith("rosmc_server/") and not relative.startswith(EXECUTOR)
    if ground and target.startswith(EXECUTOR):
        return "the executor runs on the robot: the ground shares only rosmc_server.core with it"
    if relative.startswith(EXECUTOR) and target.startswith(GROUND_ONLY):
        return "the ground's modules: the executor shares rosmc_server/common with the ground"
    if layer == "app" and module.startswith(CONVERSIONS) and not is_ros_adapter(relative):
        return "message conversions: apps get core objects from the client"
    if layer == "app" and module.startswith(("rosmc_server.ros", COMMON_ROS)):
        gui_model = not (is_ros_adapter(relative) or is_gui_entry(relative))
        if relative.startswith(GUI_PACKAGES) and gui_model:
            return "rosmc_server.ros: a GUI model or widget gets it from the GUI's ROS adapter"
        ours = module == "rosmc_server.ros" or module.startswith((*FOR_APPS, COMMON_ROS))
        if not ours:
            return "the server's ROS adapters: apps go through the client"
    return None


def imported_modules(path: Path, root: Path = REPO) -> set[str]:
    """The absolute names a module imports (each ``from x import y`` also as ``x.y``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return {module for _, module in _imported(tree, path, root)}


def _type_only_lines(tree: ast.AST) -> set[int]:
    """Lines of imports inside ``if TYPE_CHECKING:`` (seen by the type checker only)."""
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.attr if isinstance(test, ast.Attribute) else getattr(test, "id", "")
            if name == "TYPE_CHECKING":
                lines |= {
                    inner.lineno
                    for statement in node.body
                    for inner in ast.walk(statement)
                    if isinstance(inner, (ast.Import, ast.ImportFrom))
                }
    return lines


def _names_client_types(relative: str, module: str, line: int, type_only: set[int]) -> bool:
    """A GUI module naming the client's types for the type checker only."""
    client = module == CLIENT or module.startswith(CLIENT + ".")
    return client and line in type_only and relative.startswith(GUI_PACKAGES)


def scan(path: Path, root: Path = REPO) -> list[Violation]:
    """The forbidden imports of one module of the rosmc_* packages."""
    relative = path.relative_to(root).as_posix()
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    type_only = _type_only_lines(tree)
    violations = []
    for line, module in _imported(tree, path, root):
        top = module.split(".")[0]
        if _names_client_types(relative, module, line, type_only):
            why = None
        elif top.startswith("rosmc_"):
            why = _inside_rule(relative, module, root)
        else:
            why = None if _outside_rule(relative, top) else WHY[top]
        if why is not None:
            violations.append(Violation(relative, line, module, why))
    return violations
