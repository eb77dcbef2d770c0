"""The package builds four ways, and each result finds its messages, scripts and launch files.

Every build goes to a temporary folder and starts from a fresh shell's environment (no env.sh),
exactly as docs/workspace.md tells a user to do it. The catkin and colcon workspaces are built
once per module and shared: every launch file is then loaded from both install spaces (what
roslaunch would start, with every file it names), and the simulated team is started from one.
"""

from __future__ import annotations

import json
import os
import shlex
import xmlrpc.client
from pathlib import Path
from typing import Any

import pytest

from rosmc_server.interface import service_name
from tests.conftest import LaunchProcess, free_port, log_tail, wait_until
from tests.integration.conftest import Run, run_in_workspace
from tests.integration.test_launch_files import REQUIRED_ARGS
from tests.integration.workspaces import (
    JOBS,
    PYTHON_MESSAGES_ONLY,
    SYSTEM_PYTHON,
    CatkinWorkspace,
    Workspace,
    build_colcon_workspace,
)

REPO_ROOT = Path(__file__).resolve().parents[2]
DATA_SUFFIXES = {".yaml", ".yml", ".json", ".xml", ".rviz", ".ui", ".png", ".svg", ".urdf"}

pytestmark = pytest.mark.slow


def python_packages() -> list[str]:
    """Every rosmc_* package and subpackage of the checkout, dotted."""
    return sorted(
        ".".join(init.parent.relative_to(REPO_ROOT).parts)
        for init in REPO_ROOT.glob("rosmc_*/**/__init__.py")
        if "__pycache__" not in init.parts
    )


def package_files() -> list[str]:
    """Modules and data files below the rosmc_* packages, relative to the repo root."""
    return sorted(
        path.relative_to(REPO_ROOT).as_posix()
        for path in REPO_ROOT.glob("rosmc_*/**/*")
        if path.is_file()
        and "__pycache__" not in path.parts
        and (path.suffix == ".py" or path.suffix in DATA_SUFFIXES)
        and path.parts[len(REPO_ROOT.parts)] != "rosmc_msgs"
    )


def entry_scripts() -> list[str]:
    return sorted(path.name for path in (REPO_ROOT / "scripts").iterdir() if path.is_file())


def launch_files() -> list[str]:
    return sorted(path.name for path in (REPO_ROOT / "launch").glob("*.launch"))


def top_level_imports() -> str:
    names = ["rosmc.msg", "rosmc.srv", *(name for name in python_packages() if "." not in name)]
    return f"import {', '.join(names)}; print(rosmc.msg.__file__)"


# `sed -n 1p` reads everything: piped into `head -n 1`, rosmsg/rossrv die of a broken pipe now
# and then, which fails the script under pipefail.
PRINT_LOOKUPS = f"""
rospack find rosmc
rosrun --prefix echo rosmc rosmc_demo
roslaunch --files rosmc mission_server.launch
roslaunch --nodes rosmc mission_server.launch
{SYSTEM_PYTHON} -c '{top_level_imports()}'
rosmsg show rosmc/Pose6D | sed -n 1p
rossrv show rosmc/AddSkill | sed -n 1p
"""

# What an entry script does first: find the project's PyPI packages (rosmc_server/venv.py),
# then import them. Prints the venv it used and where mcap and pybullet came from.
PYPI_IMPORTS = f"""{SYSTEM_PYTHON} -c 'from rosmc_server.venv import use_project_venv
print(use_project_venv())
import mcap, pybullet, rosbags
print(mcap.__file__)'
"""


def check_lookups(lines: list[str], share: Path, script: Path, launch: Path, python: Path) -> None:
    """Check the output of PRINT_LOOKUPS, one line each."""
    assert lines[0] == str(share)
    assert lines[1] == str(script)
    assert lines[2] == str(launch / "mission_server.launch")
    assert lines[3] == "/rosmc/mission_server"
    assert Path(lines[4]).is_relative_to(python), lines[4]
    assert lines[5:7] == ["float64 x", "uint64 base_revision"], lines[5:]


def check_pypi_packages(setup: Path, env: dict[str, str], venv: Path) -> None:
    """Outside env.sh an entry script finds the PyPI packages in ``venv``."""
    lines = run_in_workspace(setup, PYPI_IMPORTS, env)
    assert lines[0] == str(venv), lines
    assert Path(lines[1]).is_relative_to(venv), lines


def test_standalone_cmake_build(tmp_path: Path, clean_env, run, in_workspace) -> None:
    build = tmp_path / "build"
    run(["cmake", "-S", REPO_ROOT, "-B", build, f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}"], clean_env)
    run(["make", "-C", build, JOBS], clean_env)

    devel = build / "devel"
    lines = in_workspace(devel / "setup.bash", PRINT_LOOKUPS, clean_env)
    check_lookups(
        lines,
        share=REPO_ROOT,
        script=devel / "lib" / "rosmc" / "rosmc_demo",  # catkin's devel-space relay
        launch=REPO_ROOT / "launch",
        python=devel / "lib" / "python3" / "dist-packages",
    )
    check_pypi_packages(devel / "setup.bash", clean_env, REPO_ROOT / ".venv")
    if (REPO_ROOT / "rosmc_server" / "demo.py").exists():
        # The relay runs the script in scripts/ with Debian's python.
        lines = in_workspace(devel / "setup.bash", "rosrun rosmc rosmc_demo --help", clean_env)
        assert lines[0].startswith("usage: rosmc_demo")


@pytest.fixture(scope="module")
def colcon_ws(tmp_path_factory: pytest.TempPathFactory) -> Workspace:
    """The checkout built with ``colcon build``, once for the module."""
    return build_colcon_workspace(tmp_path_factory.mktemp("colcon_ws"))


def test_catkin_make_devel_space(catkin_ws: CatkinWorkspace) -> None:
    devel = catkin_ws.devel
    lines = run_in_workspace(devel / "setup.bash", PRINT_LOOKUPS, catkin_ws.env)
    check_lookups(
        lines,
        share=catkin_ws.source,
        script=devel / "lib" / "rosmc" / "rosmc_demo",
        launch=catkin_ws.source / "launch",
        python=devel / "lib" / "python3" / "dist-packages",
    )
    check_pypi_packages(devel / "setup.bash", catkin_ws.env, REPO_ROOT / ".venv")


def test_catkin_make_install_space(catkin_ws: CatkinWorkspace) -> None:
    install = catkin_ws.install
    lines = run_in_workspace(install.setup, PRINT_LOOKUPS, install.env)
    check_install_space(lines, install.prefix, install.share, install.prefix / "lib" / "rosmc")
    # An install space has no checkout beside it: ROSMC_VENV names the venv.
    venv_env = {**install.env, "ROSMC_VENV": str(REPO_ROOT / ".venv")}
    check_pypi_packages(install.setup, venv_env, REPO_ROOT / ".venv")


def test_install_space_without_a_venv_says_what_to_install(catkin_ws: CatkinWorkspace) -> None:
    # This machine's Debian python has no mcap (requirements.txt puts it in .venv only).
    install = catkin_ws.install
    command = "rosrun rosmc rosmc --help 2>&1 && echo 'exit 0' || echo \"exit $?\""
    lines = run_in_workspace(install.setup, command, install.env)
    assert lines[-1] == "exit 1", lines
    assert len(lines) == 2, "one sentence, no traceback"
    assert lines[0].startswith("rosmc: the Python module 'mcap'"), lines
    assert "rosdep install --from-paths src --ignore-src -y" in lines[0]
    assert "ROSMC_VENV" in lines[0]


def test_catkin_build(tmp_path: Path, clean_env: dict[str, str], run: Run) -> None:
    # catkin_tools' `catkin build`, with its default linked devel space.
    clean_env.update(PYTHON_MESSAGES_ONLY)
    (tmp_path / "ws" / "src").mkdir(parents=True)
    source = tmp_path / "ws" / "src" / "rosmc"
    source.symlink_to(REPO_ROOT, target_is_directory=True)
    workspace = tmp_path / "ws"
    run(["catkin", "init"], clean_env, cwd=workspace)
    cmake_args = ["--cmake-args", f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}"]
    run(["catkin", "build", "--no-status", *cmake_args], clean_env, cwd=workspace)

    devel = workspace / "devel"
    lines = run_in_workspace(devel / "setup.bash", PRINT_LOOKUPS, clean_env)
    check_lookups(
        lines,
        share=source,
        script=devel / "lib" / "rosmc" / "rosmc_demo",
        launch=source / "launch",
        python=devel / "lib" / "python3" / "dist-packages",
    )
    check_pypi_packages(devel / "setup.bash", clean_env, REPO_ROOT / ".venv")


def check_install_space(lines: list[str], prefix: Path, share: Path, bin_dir: Path) -> None:
    """An install space holds every script, launch file, module and data file of the repo."""
    site = prefix / "lib" / "python3" / "dist-packages"
    check_lookups(lines, share, bin_dir / "rosmc_demo", share / "launch", site)
    for name in entry_scripts():
        script = bin_dir / name
        assert script.is_file() and os.access(script, os.X_OK), script
        assert script.read_text().startswith("#!/usr/bin/env python3\n"), script
    for name in launch_files():
        assert (share / "launch" / name).is_file(), name
    for rel in package_files():
        assert (site / rel).is_file(), f"{rel} is not installed"
    if (REPO_ROOT / "rosmc_server" / "config").is_dir():
        assert (share / "rosmc_server" / "config").is_dir()
    for init in REPO_ROOT.glob("rosmc_*/__init__.py"):  # mypy reads installed annotations
        assert (site / init.parent.name / "py.typed").is_file(), init.parent.name


def test_colcon_build(colcon_ws: Workspace) -> None:
    lines = run_in_workspace(colcon_ws.setup, PRINT_LOOKUPS, colcon_ws.env)
    prefix = colcon_ws.prefix
    check_install_space(lines, prefix, colcon_ws.share, prefix / "lib" / "rosmc")


LAUNCH_PROBE = Path(__file__).resolve().parent / "launch_probe.py"
INSTALL_SPACES = ["catkin_make install", "colcon build"]


def install_space(request: pytest.FixtureRequest, space: str) -> Workspace:
    """The install space named in INSTALL_SPACES (its module fixture is built on first use)."""
    if space == "catkin_make install":
        workspace: CatkinWorkspace = request.getfixturevalue("catkin_ws")
        return workspace.install
    colcon: Workspace = request.getfixturevalue("colcon_ws")
    return colcon


def probe_launch(workspace: Workspace, launch: str, args: list[str], cwd: Path) -> Any:
    """What launch_probe.py says of ``roslaunch rosmc LAUNCH ARGS`` in ``workspace``."""
    argv = [SYSTEM_PYTHON, LAUNCH_PROBE, "rosmc", launch, *args]
    command = shlex.join(str(arg) for arg in argv)
    return json.loads(run_in_workspace(workspace.setup, command, workspace.env, cwd=cwd)[-1])


def strings(value: object) -> list[str]:
    """Every string inside a parameter value (lists and dicts included), split at spaces."""
    if isinstance(value, str):
        return value.split()
    if isinstance(value, dict):
        return [s for item in value.values() for s in strings(item)]
    if isinstance(value, list):
        return [s for item in value for s in strings(item)]
    return []


@pytest.mark.parametrize("launch", launch_files())
@pytest.mark.parametrize("space", INSTALL_SPACES)
def test_launch_file_works_from_an_install_space(
    space: str, launch: str, request: pytest.FixtureRequest, tmp_path: Path
) -> None:
    workspace = install_space(request, space)
    found = probe_launch(workspace, launch, REQUIRED_ARGS.get(launch, []), tmp_path)

    root = workspace.setup.parent
    for name in found["files"]:  # roslaunch reads roscore.xml from Debian's /etc/ros first
        roscore = name.endswith("/etc/ros/roscore.xml")
        assert roscore or Path(name).parent == workspace.share / "launch", name
    for node, node_argv in found["nodes"].items():
        if not node_argv[0].startswith("/usr/"):  # rviz comes from Debian
            assert Path(node_argv[0]).parent == workspace.prefix / "lib" / "rosmc", node
    named = [s for value in found["params"].values() for s in strings(value)]
    named += [s for node_argv in found["nodes"].values() for s in node_argv]
    for path in (s for s in named if s.startswith(str(root))):
        assert Path(path).exists(), f"{launch} names {path}, which is not installed"
    assert not [s for s in named if str(REPO_ROOT) in s], "nothing reaches into the checkout"


def test_install_space_runs_the_simulated_team(
    catkin_ws: CatkinWorkspace, launch_process: LaunchProcess, tmp_path: Path
) -> None:
    install = catkin_ws.install
    args = ["sim:=true", "rviz:=false", "command_gui:=false"]
    nodes = set(probe_launch(install, "operator.launch", args, tmp_path)["nodes"])
    assert {"/rosmc/mission_server", "/rosmc/sim", "/rosmc/team_executors"} <= nodes
    nodes |= {f"/{robot}/mission_executor" for robot in ("drone", "science_rover")}
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    env = {**install.env, "ROSMC_VENV": str(REPO_ROOT / ".venv"), "ROS_IP": "127.0.0.1"}
    launch = shlex.join(["roslaunch", "rosmc", "operator.launch", *args, "-p", str(port)])
    script = f"source {install.setup} && export ROS_MASTER_URI={uri} && exec {launch}"
    process = launch_process(["bash", "-c", script], env=env, name="operator", cwd=tmp_path)

    def team_is_up() -> bool:
        assert process.poll() is None, f"roslaunch ended:\n{log_tail(process.log_path)}"
        try:
            _, _, (publishers, _, services) = xmlrpc.client.ServerProxy(uri).getSystemState("/t")
        except OSError:
            return False  # the master is not up yet
        running = {node for _, names in publishers + services for node in names}
        clock = [names for topic, names in publishers if topic == "/clock"]
        offered = {name for name, _ in services}
        return (
            nodes <= running
            and clock == [["/rosmc/sim"]]
            and (service_name("get_mission") in offered)
        )

    wait_until(team_is_up, timeout=180, what="the team from the install space is up", period=0.5)
    assert process.poll() is None, log_tail(process.log_path)


def machine_paths(root: Path, forbidden: list[str]) -> list[str]:
    """Files below ``root`` whose name or text holds one of the ``forbidden`` paths.

    Compiled caches (``__pycache__``) are left out: Python records in them the path it
    compiled, for tracebacks only.
    """
    found = []
    for path in sorted(root.rglob("*")):
        if "__pycache__" in path.parts or path.is_dir():
            continue
        rel = path.relative_to(root).as_posix()
        if any(f in str(path.resolve()) or f.lstrip("/") in rel for f in forbidden):
            found.append(f"{rel} (its path)")
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue
        found += [f"{rel} names {f}" for f in forbidden if f in text]
    return found


@pytest.mark.parametrize("space", INSTALL_SPACES)
def test_an_install_space_is_relocatable_and_holds_each_definition_once(
    space: str, request: pytest.FixtureRequest
) -> None:
    workspace = install_space(request, space)
    # The checkout, the workspace's src/ (a link to it) and build/ (both layouts have one
    # beside install/).
    root = workspace.setup.parent.parent
    forbidden = [str(REPO_ROOT), str(root / "src"), str(root / "build")]
    assert machine_paths(workspace.prefix, forbidden) == []

    definitions = [p.relative_to(workspace.share).as_posix() for p in workspace.share.rglob("*")]
    msgs = sorted(d for d in definitions if d.endswith(".msg"))
    srvs = sorted(d for d in definitions if d.endswith(".srv"))
    assert msgs == sorted(f"msg/{p.name}" for p in (REPO_ROOT / "rosmc_msgs" / "msg").iterdir())
    assert srvs == sorted(f"srv/{p.name}" for p in (REPO_ROOT / "rosmc_msgs" / "srv").iterdir())
    paths = (workspace.share / "cmake" / "rosmc-msg-paths.cmake").read_text()
    assert '_prepend_path("${rosmc_DIR}/.." "msg" rosmc_MSG_INCLUDE_DIRS UNIQUE)' in paths
