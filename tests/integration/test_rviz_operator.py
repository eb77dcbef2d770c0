"""The operator's rviz for real: ``rviz/operator.rviz`` against a server, the sim and the markers.

A real master, mission server, sim node (sim time, real-time factor 20) and marker node;
a mission with a blueprint pose marker and a synchronized-then-finished area; real rviz
under Xvfb (``tools/rviz_screenshot.py``). The screenshot is checked where things must be:
the camera of the config is projected (rviz's orbit camera: vertical field of view, looking
at the focal point) and the pixels near each projected position must show the robot body's
colour, the task marker's colour and the status icons' text colours (unlit: exact).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from rosmc_rviz_markers.core import icons
from rosmc_rviz_markers.core.icons import block_centre
from rosmc_rviz_markers.core.scene import UNHEARD_AT
from rosmc_server.core import MarkerType, Pose, TaskMarker
from rosmc_server.ros.client import MissionClient
from tests.conftest import LaunchProcess, RosMaster
from tests.integration.markers_fixtures import wait_for
from tests.integration.test_rviz import gui_programs, load_tool, sim  # noqa: F401

pytest_plugins = ["tests.integration.server_fixtures"]

REPO = Path(__file__).resolve().parents[2]
CONFIG = REPO / "rviz" / "operator.rviz"
ROBOT_START = {"drone": (0.0, 0.0), "science_rover": (3.5, -3.5)}
POSE_MARKER = (-6.0, -9.0)


def config() -> dict[str, Any]:
    """The operator config as YAML."""
    document: dict[str, Any] = yaml.safe_load(CONFIG.read_text())
    return document


def project(point: tuple[float, float, float], width: int, height: int) -> tuple[float, float]:
    """Pixel (column, row) of a map point in the 3D view, with the config's orbit camera."""
    view = config()["Visualization Manager"]["Views"]["Current"]
    focal = np.array([view["Focal Point"][k] for k in ("X", "Y", "Z")], dtype=float)
    d, pitch, yaw = view["Distance"], view["Pitch"], view["Yaw"]
    eye = focal + d * np.array(
        [math.cos(yaw) * math.cos(pitch), math.sin(yaw) * math.cos(pitch), math.sin(pitch)]
    )
    forward = (focal - eye) / np.linalg.norm(focal - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    v = np.array(point, dtype=float) - eye
    depth = v @ forward
    half = math.tan(view["Field of View"] / 2)
    x = (v @ right) / (depth * half * width / height)
    y = (v @ up) / (depth * half)
    return width / 2 * (1 + x), height / 2 * (1 - y)


def near(pixels: np.ndarray, at: tuple[float, float], radius: int) -> np.ndarray:
    """The pixels of the square of ``radius`` around ``at``."""
    col, row = round(at[0]), round(at[1])
    return pixels[max(row - radius, 0) : row + radius, max(col - radius, 0) : col + radius]


@pytest.fixture
def server(start_server: Any) -> Any:
    """A mission server on the session's master."""
    return start_server()


@pytest.fixture
def markers(server: Any, launch_process: LaunchProcess, ros_master: RosMaster) -> Iterator[Any]:
    """The marker node following the server."""
    node = launch_process(
        [sys.executable, str(REPO / "scripts" / "markers_node")],
        env=ros_master.env,
        name="markers_node",
        cwd=REPO,
    )
    wait_for(lambda: "markers for library" in node.log(), "the marker node", 30.0)
    yield node


@pytest.mark.usefixtures("gui_programs", "sim")
def test_operator_rviz_shows_robots_markers_and_icons(
    markers: Any, ros_master: RosMaster, tmp_path: Path
) -> None:
    client = MissionClient(10.0)
    client.get_mission()
    name = client.add_task_marker(TaskMarker("goal", MarkerType.POSE, Pose(*POSE_MARKER))).name
    client.add_skill("science_rover", "navigate_to", bindings={"target": name})
    tool = load_tool()
    background = tool.config_background(CONFIG)
    text_colors = [
        tuple(round(255 * c) for c in (col.r, col.g, col.b))
        for col in (icons.GOOD, icons.WARN, icons.BAD, icons.DIM, icons.NEUTRAL)
    ]
    check = tool.DrawnCheck(
        background=background, min_colors=100, expect_colors=(text_colors[3],), tolerance=20
    )
    output = tmp_path / "operator.png"
    result = tool.take_screenshot(
        CONFIG,
        output,
        timeout=40.0,
        settle=3.0,
        check=check,
        env=ros_master.env,
        log=tmp_path / "rviz.log",
    )
    assert not result.problems, result.problems
    view = result.shot.view(background)
    assert view is not None
    px = view.pixels.astype(np.int16)
    w, h = view.width, view.height
    red, green, blue = px[..., 0], px[..., 1], px[..., 2]

    # the science rover's body: yellow (lit), at its start pose
    rover = near(px, project((*ROBOT_START["science_rover"], 0.4), w, h), 30)
    yellow = (rover[..., 0] > 150) & (rover[..., 1] > 100) & (rover[..., 2] < 100)
    assert yellow.sum() > 20, "no science rover body where it stands"
    # the blueprint pose marker: its flag and disc in the blueprint blue
    flag = near(px, project((*POSE_MARKER, 0.8), w, h), 35)
    bluish = (flag[..., 2] > flag[..., 0] + 60) & (flag[..., 2] > 110)
    assert bluish.sum() > 30, "no blueprint task marker where it lies"
    # the status icons above the drone: two lines around the block's centre
    # (no robot reports a pose here, so the drone, first, stays at level 0)
    centre = block_centre(0)
    block = near(px, project((*ROBOT_START["drone"], centre), w, h), 60)
    text = np.zeros(block.shape[:2], dtype=bool)
    for color in text_colors:
        text |= np.all(np.abs(block - np.array(color)) <= 20, axis=2)
    assert text.sum() > 40, "no status icon text above the drone"
    # and nowhere near an empty corner of the site
    empty = near(px, project((-30.0, 30.0, 0.0), w, h), 30)
    assert (
        empty.size == 0
        or not ((empty[..., 0] > 150) & (empty[..., 1] > 100) & (empty[..., 2] < 100)).any()
    )
    del red, green, blue


@pytest.fixture
def spare_markers(
    start_server: Any, launch_process: LaunchProcess, ros_master: RosMaster, tmp_path: Path
) -> Iterator[Any]:
    """A server whose library has a robot the sim does not run ("spare"), and the markers."""
    shipped = (REPO / "rosmc_server" / "config" / "mars_team.yaml").read_text()
    spare = "  spare: {kind: dynamic, model: drone_scout, description: Not started.}\n"
    library = tmp_path / "spare.yaml"
    library.write_text(shipped.replace("\nagents:\n", "\nagents:\n" + spare))
    start_server(library=str(library))
    node = launch_process(
        [sys.executable, str(REPO / "scripts" / "markers_node")],
        env=ros_master.env,
        name="markers_node",
        cwd=REPO,
    )
    wait_for(lambda: "agents without TF: spare" in node.log(), "the spare robot noticed", 30.0)
    yield node


@pytest.mark.usefixtures("gui_programs", "sim")
def test_a_robot_without_tf_leaves_the_others_drawn(
    spare_markers: Any, ros_master: RosMaster, tmp_path: Path
) -> None:
    # rviz draws no marker of an update until it can transform each one: the spare robot,
    # which has no TF frame, must not keep the others from being drawn.
    tool = load_tool()
    background = tool.config_background(CONFIG)
    output = tmp_path / "spare.png"
    check = tool.DrawnCheck(background=background, min_colors=100, tolerance=20)
    result = tool.take_screenshot(
        CONFIG,
        output,
        timeout=40.0,
        settle=3.0,
        check=check,
        env=ros_master.env,
        log=tmp_path / "rviz.log",
    )
    assert not result.problems, result.problems
    view = result.shot.view(background)
    assert view is not None
    px = view.pixels.astype(np.int16)
    w, h = view.width, view.height
    rover = near(px, project((*ROBOT_START["science_rover"], 0.4), w, h), 30)
    yellow = (rover[..., 0] > 150) & (rover[..., 1] > 100) & (rover[..., 2] < 100)
    # its body, not only the yellow text of the status icons beside it (about 80 pixels)
    assert yellow.sum() > 500, "no science rover body where it stands"
    # the spare drone waits, not heard, in the map frame beside the lander (its blue body)
    spare = near(px, project((*UNHEARD_AT, 0.5), w, h), 35)
    blue = (spare[..., 2] > 150) & (spare[..., 2] > spare[..., 0] + 60)
    assert blue.sum() > 20, "the spare robot is not drawn where robots without TF wait"
    assert "agents without TF: spare" in spare_markers.log()
    print(f"screenshot: {output}")
