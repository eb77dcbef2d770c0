"""The operator station on one 1600x1000 screen, and its two windows opening each other.

One real ``roslaunch rosmc operator.launch sim:=true`` on its own master and a virtual
screen (Xvfb), without rviz and the command window at first; the command window is started
as an operator starts it (``rosmc_command``). Driven with the mouse through ``xdotool``:

* the command window opens on the right part of the screen;
* its *Show 3D view* button starts rviz, which opens on the left part, beside it: both
  inside the screen, no overlap;
* the mission clock over the lander in rviz advances with the simulation;
* with the command window closed, rviz's station marker (*[ command window ]* over the
  clock: a click opens its menu, then *Open command window*) starts a command window
  again, in its place beside rviz;
* *Show 3D view* with rviz running brings rviz forward and starts no second rviz.

At 1280x800 and 1920x1080 the whole ``operator.launch`` opens both windows side by side,
inside the screen, without overlap (rviz's own minimum width fits its part).
"""

from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
import time
import xmlrpc.client
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import rosgraph

from tests.conftest import LaunchProcess, wait_until
from tests.integration.test_rviz import gui_programs  # noqa: F401
from tests.integration.test_rviz_operator import CONFIG, project

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tools" / "station_screenshot.py"
SIZE = (1600, 1000)
START = 180.0  # the simulated team, rviz under software OpenGL, on two busy cores
STATION_AT = (0.0, 0.0, 11.4)  # the menu's label: rosmc_rviz_markers/ros/station_layer.py
RVIZ_VIEW = "/rviz_operator_view"


def load_tool() -> ModuleType:
    """``tools/station_screenshot.py`` as a module (tools/ is not a package)."""
    spec = importlib.util.spec_from_file_location("station_screenshot", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def nodes(uri: str) -> set[str]:
    """Every node the master at ``uri`` knows now."""
    try:
        state = rosgraph.Master("/station_test", uri).getSystemState()
    except (rosgraph.MasterError, OSError):
        return set()  # the master is not up yet
    publishers, subscribers, _services = state
    return {node for _topic, names in (*publishers, *subscribers) for node in names}


def pid(uri: str, node: str) -> int | None:
    """The process id of ``node`` (None if it is not there)."""
    try:
        node_uri = rosgraph.Master("/station_test", uri).lookupNode(node)
        return int(xmlrpc.client.ServerProxy(node_uri).getPid("/station_test")[2])
    except (rosgraph.MasterError, OSError, xmlrpc.client.Error):
        return None


def clock_seconds(env: dict[str, str]) -> int | None:
    """The seconds the mission clock in rviz shows (None before it shows a time)."""
    result = subprocess.run(
        ["rostopic", "echo", "-n", "1", "/rosmc/markers/clock"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    found = re.search(r'text: "mission time (\d+):(\d\d):(\d\d)"', result.stdout)
    if found is None:
        return None
    hours, minutes, seconds = map(int, found.groups())
    return hours * 3600 + minutes * 60 + seconds


@pytest.mark.usefixtures("gui_programs")
def test_the_station_fits_one_screen_and_its_windows_open_each_other(
    launch_process: LaunchProcess, tmp_path: Path
) -> None:
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is not installed (make setup installs it)")
    tool = load_tool()
    with tool.station_screen(SIZE, tmp_path / "home") as station:
        env = dict(station.env)
        uri = env["ROS_MASTER_URI"]
        display = station.display
        args = ["sim:=true", "rviz:=false", "command_gui:=false", f"journal_dir:={tmp_path}"]
        launch = ["roslaunch", "-p", str(station.port), "rosmc", "operator.launch", *args]
        launch_process(launch, env=env, name="station", cwd=tmp_path)

        def shot(name: str) -> Path:
            path = tmp_path / f"{name}.png"
            tool.shots.grab(display).write_png(path)
            return path

        def click(x: int, y: int, button: int = 1) -> None:
            tool.xdotool(display, "mousemove", "--sync", str(x), str(y))
            time.sleep(0.3)  # rviz picks what lies under the pointer when it moves
            tool.xdotool(display, "click", str(button))

        # The command window, as an operator starts it: the right part of the screen.
        wait_until(lambda: "/rosmc/markers" in nodes(uri), START, "the station up")
        first = launch_process(["rosmc_command"], env=env, name="command_window")
        command = wait_until(lambda: tool.command_window(display), START, "the command window")
        assert command.x + command.width == SIZE[0] and command.width <= 800, command

        # Its Show 3D view button (the menu bar's right corner) starts rviz, on the left.
        wait_until(
            lambda: any(n.startswith("/rosmc_command_") for n in nodes(uri)), START, "its node"
        )
        time.sleep(2.0)  # the window has joined the ROS graph (its clock runs)
        click(command.x + command.width - 45, command.y + 12)
        rviz = wait_until(lambda: tool.rviz_window(display), START, f"rviz ({shot('3d')})")
        command = tool.command_window(display)
        assert command is not None
        assert not rviz.overlaps(command), f"{rviz} overlaps {command} ({shot('overlap')})"
        for box in (rviz, command):
            assert box.x >= 0 and box.y >= 0, box
            assert box.x + box.width <= SIZE[0] and box.y + box.height <= SIZE[1], box
        assert rviz.x == 0 and rviz.width >= 800, rviz
        rviz_pid = wait_until(lambda: pid(uri, RVIZ_VIEW), START, "rviz's node")

        # The mission clock over the lander advances with the simulation.
        start = wait_until(lambda: clock_seconds(env), START, "the mission clock in rviz")
        wait_until(lambda: (clock_seconds(env) or 0) > start, 60, "the clock advancing")

        # The command window closes; rviz's station marker opens one again.
        first.terminate()
        first.wait(timeout=30)
        wait_until(lambda: tool.command_window(display) is None, 30, "the window gone")
        screen = tool.shots.grab(display)
        background = tool.shots.config_background(CONFIG)
        box = screen.view_box(background)
        assert box is not None, f"no 3D view on the screen ({shot('no_view')})"
        left, top, width, height = box
        col, row = project(STATION_AT, width, height)
        click(left + round(col), top + round(row))  # a click on the label: its menu
        time.sleep(1.0)
        menu_shot = shot("menu")
        tool.xdotool(display, "key", "Down", "Return")  # its entry: Open command window
        again = wait_until(
            lambda: tool.command_window(display), START, f"a command window ({menu_shot})"
        )
        assert again.x + again.width == SIZE[0] and not again.overlaps(rviz), again
        assert any(n.startswith("/rosmc_command_") for n in nodes(uri))

        # Show 3D view with rviz running brings it forward: no second rviz.
        time.sleep(2.0)  # the new window has joined the ROS graph
        click(again.x + again.width - 45, again.y + 12)
        time.sleep(3.0)
        assert pid(uri, RVIZ_VIEW) == rviz_pid
        assert len(tool.windows(display, "--class", "rviz")) >= 1
        view_nodes = [n for n in nodes(uri) if n.startswith("/rviz_operator")]
        assert sorted(view_nodes) == ["/rviz_operator", RVIZ_VIEW], view_nodes
        shot("station")


@pytest.mark.usefixtures("gui_programs")
@pytest.mark.parametrize("size", [(1280, 800), (1920, 1080)], ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_station_fits_smaller_and_larger_screens(
    launch_process: LaunchProcess, tmp_path: Path, size: tuple[int, int]
) -> None:
    if shutil.which("xdotool") is None:
        pytest.fail("xdotool is not installed (make setup installs it)")
    tool = load_tool()
    with tool.station_screen(size, tmp_path / "home") as station:
        args = ["sim:=true", f"journal_dir:={tmp_path}"]
        launch = ["roslaunch", "-p", str(station.port), "rosmc", "operator.launch", *args]
        launch_process(launch, env=dict(station.env), name="station", cwd=tmp_path)
        display = station.display

        def both() -> tuple[Any, Any] | None:
            command, rviz = tool.command_window(display), tool.rviz_window(display)
            return (command, rviz) if command and rviz else None

        command, rviz = wait_until(both, START, "both windows")
        time.sleep(3.0)  # rviz has laid out its panels: a minimum width would show now
        command, rviz = both() or (command, rviz)
        shot = tmp_path / "station.png"
        tool.shots.grab(display).write_png(shot)
        assert not rviz.overlaps(command), f"{rviz} overlaps {command} ({shot})"
        for box in (rviz, command):
            assert box.x >= 0 and box.x + box.width <= size[0], f"{box} ({shot})"
            assert box.y >= 0 and box.y + box.height <= size[1], f"{box} ({shot})"
        assert rviz.x == 0 and command.x + command.width == size[0]
