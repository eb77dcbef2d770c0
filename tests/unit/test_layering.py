"""Layering: the rules of ``layering_rules.py`` hold for every module of the packages.

The rules (the order core < conversions < recording < ros < client < app, and who may
import rospy, messages, Qt and pybullet) are described in
:mod:`tests.unit.layering_rules`. Besides scanning every module, a test imports every
core package with the forbidden modules blocked, which also catches imports that happen
indirectly; and the scanner is tested on small made-up repositories.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.unit.layering_rules import (
    GUI_PACKAGES,
    LAYER_OF_PATH,
    MESSAGES,
    PYBULLET,
    PYBULLET_ALLOWED,
    QT,
    REPO,
    ROS_RUNTIME,
    core_modules,
    imported_modules,
    is_gui_entry,
    is_ros_adapter,
    layer_of,
    module_name,
    package_modules,
    scan,
)

# -- the real check ------------------------------------------------------------------


def test_there_are_core_modules_to_scan() -> None:
    modules = {p.relative_to(REPO).as_posix() for p in core_modules()}
    expected = {
        f"rosmc_server/core/{name}.py"
        for name in (
            "errors",
            "skills/params",
            "skills/library",
            "model/model",
            "model/changes",
            "model/state",
            "rules/barriers",
            "rules/editing",
            "rules/execution",
            "rules/markers",
            "rules/mission",
            "files/persistence",
            "skills/policy",
            "world/frames",
        )
    }
    assert expected <= modules


def test_the_layer_table_names_real_paths() -> None:
    assert [key for key in LAYER_OF_PATH if not (REPO / key).exists()] == []


def test_every_module_has_a_layer() -> None:
    missing = [
        p.relative_to(REPO).as_posix()
        for p in package_modules()
        if layer_of(p.relative_to(REPO).as_posix()) is None
    ]
    assert missing == [], "add these to LAYER_OF_PATH"


@pytest.mark.parametrize(
    ("relative", "layer"),
    [
        ("rosmc_server/core/rules/mission.py", "core"),
        ("rosmc_server/executor/core/engine.py", "core"),
        ("rosmc_server/interface.py", "core"),
        ("rosmc_server/conversions/mission.py", "conversions"),
        ("rosmc_server/recording/history.py", "recording"),
        ("rosmc_server/ros/server_node.py", "ros"),
        ("rosmc_server/executor/ros/node.py", "ros"),
        ("rosmc_server/ros/client/mission_client.py", "client"),
        ("rosmc_server/ros/replayer.py", "ros"),
        ("rosmc_server/text/plain.py", "core"),
        ("rosmc_server/cli/replay.py", "app"),
        ("rosmc_rviz_markers/core/labels.py", "core"),
        ("rosmc_rviz_markers/ros/node.py", "app"),
        ("rosmc_rqt_command/ros_bridge.py", "app"),
        ("rosmc_rqt_command/task_model.py", "app"),
        # any folder named core is the core layer, existing or not, at any depth
        ("rosmc_rqt_command/core/view.py", "core"),
        ("rosmc_rqt_command/core/rules/legal.py", "core"),
    ],
)
def test_layer_table(relative: str, layer: str) -> None:
    assert layer_of(relative) == layer


def test_the_table_names_real_paths() -> None:
    missing = [key for key in LAYER_OF_PATH if not (REPO / key).exists()]
    assert missing == [], "LAYER_OF_PATH names files or folders that do not exist"


def test_no_module_breaks_the_layers() -> None:
    violations = [str(v) for path in package_modules() for v in scan(path)]
    assert violations == []


@pytest.mark.parametrize("package", GUI_PACKAGES)
def test_no_gui_module_imports_itself_in_a_circle(package: str) -> None:
    """Even under TYPE_CHECKING: a circle means two modules cannot be read apart."""
    names = {".".join(module_name(path, REPO)): path for path in (REPO / package).glob("**/*.py")}
    edges = {name: imported_modules(path) & set(names) for name, path in names.items()}
    edges = {name: targets - {name} for name, targets in edges.items()}
    assert _circles(edges) == []


def _circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """One path per circle found by a depth-first search (empty: none)."""
    found: list[list[str]] = []
    done: set[str] = set()

    def visit(node: str, path: list[str]) -> None:
        if node in path:
            found.append([*path[path.index(node) :], node])
            return
        if node in done:
            return
        for target in sorted(edges[node]):
            visit(target, [*path, node])
        done.add(node)

    for start in sorted(edges):
        visit(start, [])
    return found


def test_core_packages_import_with_the_forbidden_modules_blocked() -> None:
    modules = sorted(
        {
            ".".join(module_name(path, REPO))
            for path in core_modules()
            if (path.parent / "__init__.py").exists()
            and not path.relative_to(REPO).as_posix().startswith(PYBULLET_ALLOWED)
        }
    )
    blocked = sorted(ROS_RUNTIME | MESSAGES | QT | PYBULLET)
    program = textwrap.dedent(
        f"""
        import importlib, sys
        for name in {blocked!r}:
            sys.modules[name] = None  # importing it now raises ImportError
        for module in {modules!r}:
            importlib.import_module(module)
        """
    )
    assert modules, "no core packages found"
    result = subprocess.run(
        [sys.executable, "-c", program],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-2000:]


def test_the_cli_and_recording_tools_load_without_rospy() -> None:
    """What runs without a ROS graph does not load rospy (the client loads it when used)."""
    program = textwrap.dedent(
        """
        import sys
        import rosmc_server.cli.parser, rosmc_server.conversions, rosmc_server.recording.history
        import rosmc_server.text
        assert "rospy" not in sys.modules, "rospy was imported"
        """
    )
    result = subprocess.run(
        [sys.executable, "-c", program],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-2000:]


# -- the scanner catches what it should -----------------------------------------------


@pytest.fixture
def fake_repo(tmp_path: Path) -> Path:
    for package in (
        "rosmc_server/core",
        "rosmc_sim/core",
        "rosmc_server/ros",
        "rosmc_server/ros/client",
        "rosmc_server/conversions",
        "rosmc_server/recording",
        "rosmc_server/cli",
        "rosmc_rqt_command",
        "rosmc_rqt_command/core",
        "rosmc_rviz_markers/core",
        "rosmc_rviz_markers/ros",
        "rosmc_server/common",
        "rosmc_server/common/ros",
        "rosmc_server/executor",
        "rosmc_server/executor/ros",
    ):
        (tmp_path / package).mkdir(parents=True)
        (tmp_path / package / "__init__.py").write_text("", encoding="utf-8")
    (tmp_path / "rosmc_server/ros/replayer.py").write_text("", encoding="utf-8")
    (tmp_path / "rosmc_server/ros/server_node.py").write_text("", encoding="utf-8")
    for module in ("radio", "station", "logging_bridge"):
        (tmp_path / f"rosmc_server/common/ros/{module}.py").write_text("", encoding="utf-8")
    (tmp_path / "rosmc_rviz_markers/core/labels.py").write_text("", encoding="utf-8")
    return tmp_path


BAD = [
    "import rospy",
    "import rospy as r",
    "from rospy import Publisher",
    "import genpy",
    "import roslib.message",
    "from rosmc.msg import Mission",
    "import rosmc.srv",
    "from rosmc import msg",
    "from PyQt5 import QtCore",
    "from PySide2.QtWidgets import QWidget",
    "from python_qt_binding.QtCore import Signal",
    "import pybullet",
    "import pybullet_data",
    "from ..ros import node",
    "from rosmc_server.ros.node import main",
    "from rosmc_server import ros",
    "from rosmc_server.conversions import skill_to_msg",
    "from ..recording import history",
    "importlib.import_module('rospy')",
    "__import__('PyQt5')",
    "def later():\n    import rospy",
    "if False:\n    import rospy",
    "try:\n    import rospy\nexcept ImportError:\n    rospy = None",
]


@pytest.mark.parametrize("source", BAD)
def test_scanner_catches_a_bad_import(fake_repo: Path, source: str) -> None:
    module = fake_repo / "rosmc_server" / "core" / "bad.py"
    module.write_text(source + "\n", encoding="utf-8")
    assert module in core_modules(fake_repo)
    violations = scan(module, fake_repo)
    assert len(violations) >= 1, source
    assert violations[0].path == "rosmc_server/core/bad.py"
    assert str(violations[0]).startswith("rosmc_server/core/bad.py:")


def test_scanner_self_test_import_rospy(fake_repo: Path) -> None:
    module = fake_repo / "rosmc_server" / "core" / "uses_ros.py"
    module.write_text('"""A core module that went wrong."""\n\nimport rospy\n', encoding="utf-8")
    (violation,) = scan(module, fake_repo)
    assert (violation.line, violation.module) == (3, "rospy")
    assert "ROS adapter" in violation.why


GOOD = [
    "import yaml",
    "import math, json",
    "from . import model",
    "from .model import SkillStatus",
    "from ..core import errors",
    "from rosmc_server.core.errors import RosmcError",
    "import rosmc_server.core",
    "import rospkg_like_name",
    "x = 'import rospy'",
    "# import rospy",
    "def f(importer):\n    return importer.import_module(name)",
]


@pytest.mark.parametrize("source", GOOD)
def test_scanner_allows_plain_python(fake_repo: Path, source: str) -> None:
    module = fake_repo / "rosmc_server" / "core" / "good.py"
    module.write_text(source + "\n", encoding="utf-8")
    assert scan(module, fake_repo) == []


def test_pybullet_only_in_the_sim_core(fake_repo: Path) -> None:
    sim = fake_repo / "rosmc_sim" / "core" / "world.py"
    sim.write_text("import pybullet\nimport pybullet_data\n", encoding="utf-8")
    assert scan(sim, fake_repo) == []
    sim.write_text("import pybullet\nimport rospy\n", encoding="utf-8")
    assert [v.module for v in scan(sim, fake_repo)] == ["rospy"]


def test_core_packages_are_found_at_any_depth(fake_repo: Path) -> None:
    (fake_repo / "rosmc_server" / "ros" / "node.py").write_text("import rospy\n", encoding="utf-8")
    nested = fake_repo / "rosmc_server" / "executor" / "core"
    nested.mkdir(parents=True)
    (nested / "runner.py").write_text("import rospy\n", encoding="utf-8")
    found = [p.relative_to(fake_repo).as_posix() for p in core_modules(fake_repo)]
    assert "rosmc_server/ros/node.py" not in found
    assert "rosmc_server/executor/core/runner.py" in found
    assert [v.module for v in scan(nested / "runner.py", fake_repo)] == ["rospy"]
    assert scan(fake_repo / "rosmc_server" / "ros" / "node.py", fake_repo) == []


# -- the order of the layers above the core -------------------------------------------------


def _scan_source(root: Path, relative: str, source: str) -> list[str]:
    module = root / relative
    module.parent.mkdir(parents=True, exist_ok=True)
    module.write_text(source + "\n", encoding="utf-8")
    return [v.why for v in scan(module, root)]


@pytest.mark.parametrize(
    ("relative", "source"),
    [
        # the conversions: messages yes, the ROS runtime and anything above no
        ("rosmc_server/conversions/x.py", "import rospy"),
        ("rosmc_server/conversions/x.py", "from rosmc_server.recording import history"),
        ("rosmc_server/conversions/x.py", "from ..ros import server_node"),
        # the recording: below the ROS adapters
        ("rosmc_server/recording/x.py", "from rosmc_server.ros.server_node import main"),
        ("rosmc_server/recording/x.py", "import rospy"),
        # the server's adapters (the replayer too) do not use the client
        ("rosmc_server/ros/x.py", "from .client import MissionClient"),
        ("rosmc_server/ros/replayer.py", "from .client import init_node"),
        # the ground does not use the executor (the protocol both speak is in the core)
        ("rosmc_server/conversions/x.py", "from ..executor.core import Command"),
        ("rosmc_server/ros/x.py", "from rosmc_server.executor.core.engine import Engine"),
        ("rosmc_server/core/x.py", "from ..executor import basic_skills"),
        # the text rendering speaks no messages
        ("rosmc_server/text/x.py", "from rosmc.msg import Mission"),
        ("rosmc_server/text/x.py", "from ..conversions import event_from_msg"),
        # a command-GUI core is Qt-free like every core
        ("rosmc_rqt_command/core/x.py", "from python_qt_binding import QtCore"),
        # the client is below the apps
        ("rosmc_server/ros/client/x.py", "from rosmc_server.cli import main"),
        # the CLI: no rospy, no messages, no server adapters
        ("rosmc_server/cli/x.py", "import rospy"),
        ("rosmc_server/cli/x.py", "from rosmc.msg import Mission"),
        ("rosmc_server/cli/x.py", "from ..conversions import event_from_msg"),
        ("rosmc_server/cli/x.py", "from ..ros.server_node import ServerNode"),
        # GUI models and widgets: no rospy, no messages, not even the client
        ("rosmc_rqt_command/task_model.py", "import rospy"),
        ("rosmc_rqt_command/task_model.py", "from rosmc.msg import Selection"),
        ("rosmc_rqt_command/task_model.py", "from rosmc_server.ros.client import X"),
        ("rosmc_rqt_command/plugin.py", "from rosmc.msg import Selection"),
        ("rosmc_rqt_command/standalone.py", "from rosmc_server.ros import operator_services"),
        ("rosmc_rqt_command/widgets/plugin.py", "import rospy"),
        ("rosmc_rqt_command/widgets/panel.py", "import rospy"),
        ("rosmc_rviz_markers/core/labels.py", "import rospy"),
        ("rosmc_rviz_markers/core/labels.py", "from visualization_msgs.msg import Marker"),
        ("rosmc_rviz_markers/core/labels.py", "from python_qt_binding import QtCore"),
        ("rosmc_rviz_markers/core/labels.py", "from rosmc_server.ros.client import X"),
        ("rosmc_rqt_command/core/x.py", "from rosmc_server.ros.client import MissionClient"),
        # under TYPE_CHECKING only the client's types, and only in a GUI
        ("rosmc_rqt_command/core/x.py", "if TYPE_CHECKING:\n    import rospy"),
        ("rosmc_rqt_command/core/x.py", "if TYPE_CHECKING:\n    from rosmc_server.ros import x"),
        ("rosmc_server/core/x.py", "if TYPE_CHECKING:\n    from ..ros.client import X"),
        # GUI adapters use the client, not the server's insides
        ("rosmc_rqt_command/ros_bridge.py", "from rosmc_server.ros.operator_services import X"),
        ("rosmc_rviz_markers/ros/markers.py", "from rosmc_server.ros import ground_link"),
        # Qt only in the GUIs
        ("rosmc_server/cli/x.py", "from python_qt_binding import QtWidgets"),
        # the packages in order: the server and the sim import no GUI, the server no sim
        ("rosmc_server/conversions/x.py", "from rosmc_rviz_markers.core import labels"),
        ("rosmc_server/recording/x.py", "from rosmc_rviz_markers.core import labels"),
        ("rosmc_server/core/x.py", "from rosmc_sim.core import world"),
        ("rosmc_sim/ros/x.py", "from rosmc_rviz_markers.core.labels import CHAR_WIDTH"),
        # the executor (the robot's) imports none of the ground's modules
        ("rosmc_server/executor/ros/node.py", "from rosmc_server.ros.radio import Radio"),
        ("rosmc_server/executor/ros/node.py", "from ...ros import station"),
        ("rosmc_server/executor/ros/node.py", "from rosmc_server.recording import writer"),
        # a GUI model or widget uses no ROS helper, shared or not
        ("rosmc_rqt_command/task_model.py", "from rosmc_server.common.ros import station"),
    ],
)
def test_scanner_catches_a_layer_break(fake_repo: Path, relative: str, source: str) -> None:
    assert _scan_source(fake_repo, relative, source) != [], (relative, source)


@pytest.mark.parametrize(
    ("relative", "source"),
    [
        ("rosmc_server/conversions/x.py", "import genpy\nimport rosmc.msg as wire"),
        ("rosmc_server/conversions/x.py", "from ..core import Mission"),
        ("rosmc_server/recording/x.py", "from rosmc_server.conversions import event_from_msg"),
        ("rosmc_server/recording/x.py", "import genpy\nimport rosbag"),
        ("rosmc_server/ros/x.py", "import rospy\nfrom ..recording import JournalWriter"),
        ("rosmc_server/ros/client/x.py", "import rospy\nfrom ...conversions import skill_to_msg"),
        ("rosmc_server/ros/replayer.py", "from .node_setup import init_node"),
        ("rosmc_server/ros/x.py", "from ..core.protocol import Command"),
        ("rosmc_server/executor/ros/x.py", "from ..core import Engine"),
        ("rosmc_sim/ros/x.py", "from rosmc_server.executor.core import SkillType"),
        ("rosmc_server/text/x.py", "from ..core import MissionState"),
        ("rosmc_server/cli/x.py", "from ..ros.client import MissionClient"),
        ("rosmc_server/cli/x.py", "from ..ros.replayer import RecordingReplayer"),
        ("rosmc_server/cli/x.py", "from ..recording.history import MissionHistory"),
        ("rosmc_rqt_command/ros_bridge.py", "import rospy\nfrom rosmc_server.ros.client import X"),
        ("rosmc_rqt_command/ros_bridge.py", "from python_qt_binding.QtCore import Signal"),
        (
            "rosmc_rqt_command/plugin.py",
            "from qt_gui.plugin import Plugin\nfrom . import ros_bridge",
        ),
        ("rosmc_rqt_command/plugin.py", "from rosmc_server.ros.client import init_node"),
        ("rosmc_rqt_command/standalone.py", "import rospy\nfrom rosmc_server.ros.client import X"),
        ("rosmc_rqt_command/task_model.py", "from python_qt_binding import QtCore"),
        ("rosmc_rqt_command/task_model.py", "from rosmc_server.core import MissionState"),
        (
            "rosmc_rqt_command/core/x.py",
            "if TYPE_CHECKING:\n    from rosmc_server.ros.client import MissionClient",
        ),
        ("rosmc_rviz_markers/ros/node.py", "import rospy\nfrom interactive_markers import x"),
        ("rosmc_rviz_markers/ros/node.py", "from visualization_msgs.msg import Marker"),
        ("rosmc_rviz_markers/ros/node.py", "from rosmc_server.ros.client import MissionFollower"),
        ("rosmc_rviz_markers/ros/node.py", "from rosmc_server.common.ros.logging_bridge import x"),
        ("rosmc_rviz_markers/ros/node.py", "from ..core import labels"),
        ("rosmc_rviz_markers/core/labels.py", "from rosmc_server.core.frames import yaw_of"),
        ("rosmc_rviz_markers/core/labels.py", "from rosmc_server.interface import MAP_FRAME"),
        ("rosmc_rviz_markers/core/labels.py", "from rosmc_server.core import geometry"),
        ("rosmc_server/conversions/x.py", "from ..core import geometry as geo"),
        # the executor and the ground share rosmc_server/common
        ("rosmc_server/executor/ros/node.py", "from ...common.ros.radio import Radio"),
        ("rosmc_server/executor/ros/node.py", "from rosmc_server.common.ros import station"),
        ("rosmc_server/ros/x.py", "from ..common.ros.radio import Radio"),
    ],
)
def test_scanner_allows_the_layers(fake_repo: Path, relative: str, source: str) -> None:
    assert _scan_source(fake_repo, relative, source) == []


def test_gui_entry_naming() -> None:
    assert is_gui_entry("rosmc_rqt_command/plugin.py")
    assert is_gui_entry("rosmc_rqt_command/standalone.py")
    assert not is_gui_entry("rosmc_rqt_command/widgets/plugin.py")
    assert not is_gui_entry("rosmc_server/cli/standalone.py")


def test_ros_adapter_naming() -> None:
    assert is_ros_adapter("rosmc_server/ros/server_node.py")
    assert is_ros_adapter("rosmc_rviz_markers/ros/agents.py")
    assert is_ros_adapter("rosmc_rqt_command/ros_bridge.py")
    assert is_ros_adapter("rosmc_rqt_command/node.py")
    assert not is_ros_adapter("rosmc_rqt_command/plugin.py")
    assert not is_ros_adapter("rosmc_rqt_command/widgets/tasks.py")
    assert not is_ros_adapter("rosmc_rviz_markers/core/labels.py")
    assert not is_ros_adapter("rosmc_server/core/rules/mission.py")


# -- the core's subpackages ------------------------------------------------------------


def _core_part(path: str) -> str:
    """The core subpackage a core module path is in, or its name for the foundation."""
    return path.removeprefix("rosmc_server/core/").split("/")[0].removesuffix(".py")


def test_the_core_subpackages_import_only_those_before_them() -> None:
    from rosmc_server.core import FOUNDATION, SUBPACKAGE_ORDER
    from tests.unit.import_circles import import_graph

    rank = {name: index for index, name in enumerate(SUBPACKAGE_ORDER)}
    rank.update({name: -1 for name in FOUNDATION})
    rank["__init__"] = len(SUBPACKAGE_ORDER)
    climbs = []
    for module, imported in import_graph().items():
        if not module.startswith("rosmc_server/core/"):
            continue
        in_core = (target for target in imported if target.startswith("rosmc_server/core/"))
        climbs += [
            f"{module} imports {target}"
            for target in in_core
            if rank[_core_part(target)] > rank[_core_part(module)]
        ]
    assert climbs == []


def test_every_core_module_is_in_a_subpackage_of_the_order() -> None:
    from rosmc_server.core import FOUNDATION, SUBPACKAGE_ORDER

    parts = {_core_part(p.relative_to(REPO).as_posix()) for p in core_modules()}
    core_parts = {
        _core_part(p.relative_to(REPO).as_posix())
        for p in core_modules()
        if p.relative_to(REPO).as_posix().startswith("rosmc_server/core/")
    }
    assert parts  # the scan found modules
    assert core_parts <= {*SUBPACKAGE_ORDER, *FOUNDATION, "__init__"}
