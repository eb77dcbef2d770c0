"""Every shipped launch file loads with roslaunch's own loader, with its default arguments.

roslaunch reads the XML (a ``--`` inside a comment is not XML and breaks the file), resolves
``$(find rosmc)`` and every include and argument, and builds the list of nodes; nothing is
started. The operator's launch files are also loaded with the arguments the docs show.
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


def loaded(path: Path | str, args: list[str]) -> roslaunch.config.ROSLaunchConfig:
    """The launch file (a path, or a name in launch/) as roslaunch loads it with ``args``."""
    path = REPO / "launch" / path if isinstance(path, str) else path
    config = roslaunch.config.ROSLaunchConfig()
    loader = roslaunch.xmlloader.XmlLoader()
    loader.ignore_unset_args = False  # roslaunch's own CLI sets it; a missing arg is an error
    loader.load(str(path), config, argv=["roslaunch", str(path), *args], verbose=False)
    return config


def node_names(path: Path, args: list[str]) -> list[str]:
    return [f"{node.namespace}{node.name}" for node in loaded(path, args).nodes]


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


def test_relative_paths_are_taken_from_where_roslaunch_was_typed(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    # roslaunch starts nodes in ROS_HOME; the shell's PWD is where the user typed the command.
    monkeypatch.setenv("PWD", str(tmp_path))
    rviz = loaded("rviz.launch", ["rviz_config:=views/mine.rviz"])
    assert [node.args.split()[:2] for node in rviz.nodes] == [["-d", f"{tmp_path}/views/mine.rviz"]]
    team = loaded("operator.launch", ["sim:=true"])
    with_cwd = {"/rosmc/mission_server", "/rosmc/sim", "/rosmc/team_executors"}
    for node in with_cwd:
        assert team.params[f"{node}/cwd"].value == str(tmp_path), node
    # the launch's server notes its journal there, so that a respawned one resumes it
    assert team.params["/rosmc/mission_server/station_journal"].value == ""
    assert "station_journal" not in str(loaded("mission_server.launch", []).params)


@pytest.mark.parametrize(
    ("args", "expected"),
    [([], None), (["use_sim_time:=true"], True), (["use_sim_time:=false"], False)],
)
def test_rviz_sets_use_sim_time_only_when_asked(args: list[str], expected: bool | None) -> None:
    # rviz opened beside a running simulation must not switch the simulation's clock off.
    params = loaded("rviz.launch", args).params
    value = params["/use_sim_time"].value if "/use_sim_time" in params else None
    assert value is expected
