"""package.xml declares, with its rosdep key, every module the rosmc_* packages import.

A new third-party import fails here until package.xml has its key (and this table says which
key that is), so rosdep installs everything a node imports. tests/integration/test_rosdep.py
checks that every key resolves.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

from catkin_pkg.package import parse_package

REPO = Path(__file__).resolve().parents[2]

# Import name -> the rosdep key that installs it.
IMPORT_KEYS = {
    "actionlib": "actionlib",  # skills bound to action servers
    "actionlib_msgs": "actionlib_msgs",
    "genpy": "genpy",
    "geometry_msgs": "geometry_msgs",
    "interactive_markers": "interactive_markers",
    "mcap": "python3-mcap-pip",
    "mcap_ros1": "python3-mcap-ros1-support-pip",
    "nav_msgs": "nav_msgs",
    "pybullet": "python3-pybullet-pip",
    "python_qt_binding": "python_qt_binding",
    "qt_gui": "rqt_gui",  # the rqt plugin's base class
    "rosbag": "rosbag",
    "rosgraph": "rosgraph",
    "rosgraph_msgs": "rosgraph_msgs",
    "roslib": "roslib",  # message classes of bound skills, by name
    "rospy": "rospy",
    "std_msgs": "std_msgs",
    "tf2_msgs": "tf2_msgs",
    "tf2_ros": "tf2_ros",
    "visualization_msgs": "visualization_msgs",
    "yaml": "python3-yaml",
    "zstandard": "python3-zstandard",
}


def third_party_imports() -> dict[str, str]:
    """Top-level module -> one file of the rosmc_* packages that imports it."""
    found: dict[str, str] = {}
    for path in sorted(REPO.glob("rosmc_*/**/*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for top in (name.partition(".")[0] for name in names):
                if top not in sys.stdlib_module_names and not top.startswith("rosmc"):
                    found.setdefault(top, str(path.relative_to(REPO)))
    found.pop("__future__", None)
    return found


def run_dependencies() -> set[str]:
    """The keys a node needs at run time: exec_depend and depend, conditions evaluated."""
    package = parse_package(str(REPO / "package.xml"))
    package.evaluate_conditions({"ROS_PYTHON_VERSION": "3"})
    return {dep.name for dep in package.exec_depends if dep.evaluated_condition}


def test_every_import_has_a_known_rosdep_key() -> None:
    unknown = {
        name: path for name, path in third_party_imports().items() if name not in IMPORT_KEYS
    }
    assert not unknown, f"add these imports' rosdep keys to IMPORT_KEYS and package.xml: {unknown}"


def test_package_xml_declares_every_imported_module() -> None:
    declared = run_dependencies()
    needed = {IMPORT_KEYS[name] for name in third_party_imports() if name in IMPORT_KEYS}
    assert needed - declared == set()


def test_the_launch_files_tools_are_declared() -> None:
    # roslaunch starts the launch files (rosmc_demo runs it), rviz is one of their nodes.
    assert {"roslaunch", "rviz", "rqt_gui_py", "message_runtime"} <= run_dependencies()
