"""Every shipped launch file loads with roslaunch's own loader, with its default arguments.

roslaunch reads the XML (a ``--`` inside a comment is not XML and breaks the file), resolves
``$(find rosmc)`` and every include and argument, and builds the list of nodes; nothing is
started. The operator's launch files are also loaded with the arguments the README shows.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import roslaunch.config
import roslaunch.xmlloader

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
LAUNCH_FILES = sorted((REPO / "launch").glob("*.launch"))
SKILLS = "skills:=rosmc_sim.ros.robot_skills:drone_skills"
REQUIRED_ARGS = {"executor.launch": ["robot:=r1"], "sim_executor.launch": ["robot:=drone", SKILLS]}
VARIANTS = [
    ("operator.launch", ["sim:=true"]),
    ("demo.launch", ["gui:=true"]),
    ("markers.launch", ["ns:=/replay"]),
    ("command_gui.launch", ["ns:=/replay"]),
]


def node_names(path: Path, args: list[str]) -> list[str]:
    config = roslaunch.config.ROSLaunchConfig()
    loader = roslaunch.xmlloader.XmlLoader()
    loader.ignore_unset_args = False  # roslaunch's own CLI sets it; a missing arg is an error
    loader.load(str(path), config, argv=["roslaunch", str(path), *args], verbose=False)
    return [f"{node.namespace}{node.name}" for node in config.nodes]


@pytest.mark.parametrize("path", LAUNCH_FILES, ids=lambda p: p.name)
def test_every_launch_file_loads(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # A user's shell usually has no ROS_HOME: $(env ROS_HOME) would make the file fail to load.
    monkeypatch.delenv("ROS_HOME", raising=False)
    assert node_names(path, REQUIRED_ARGS.get(path.name, []))


@pytest.mark.parametrize(("name", "args"), VARIANTS, ids=[v[0] for v in VARIANTS])
def test_the_documented_variants_load(name: str, args: list[str]) -> None:
    nodes = node_names(REPO / "launch" / name, args)
    if name == "operator.launch":
        assert {"/rosmc/mission_server", "/rosmc/markers", "/rosmc/sim"} <= set(nodes)
    if name == "demo.launch":
        assert any(n.endswith("command_gui") for n in nodes)
