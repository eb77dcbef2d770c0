"""Radio coverage in real rviz: the sim's radio model shaded by signal, last-link marks.

A real master, mission server, sim node (sim time, real-time factor 20) and marker node;
real rviz under Xvfb with ``rviz/operator.rviz`` (``tools/rviz_screenshot.py``). The
marker node's ``/rosmc/coverage`` must hold the model's cells and a labelled last-link mark
per robot (the robots' telemetry reaches it through the server's agent states), and the
screenshot must show the shading where the config's camera sees the site: warm-to-green
inside the lander's reach, none well outside it.
"""

from __future__ import annotations

import re
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rospy
from visualization_msgs.msg import MarkerArray

from rosmc_server.interface import COVERAGE_MARKERS_TOPIC
from tests.conftest import RosMaster, wait_until
from tests.integration.test_rviz import blended, gui_programs, load_tool, sim  # noqa: F401
from tests.integration.test_rviz_operator import (  # noqa: F401
    CONFIG,
    markers,
    near,
    project,
    server,
)

pytest_plugins = ["tests.integration.server_fixtures"]

ROBOTS = ("drone", "science_rover", "manipulator_rover")
LABEL = re.compile(r"^(\w+) last link: -\d+ dBm (now|\d+ s ago)$")
COVERED, UNCOVERED = (6.0, 6.0), (12.0, 25.0)  # the lander reaches 24 m on the Mars site


class LatestArray:
    """The newest MarkerArray on the coverage topic."""

    def __init__(self) -> None:
        self.last: MarkerArray | None = None
        self._lock = threading.Lock()
        self._subscriber = rospy.Subscriber(COVERAGE_MARKERS_TOPIC, MarkerArray, self._on_msg)

    def _on_msg(self, msg: MarkerArray) -> None:
        with self._lock:
            self.last = msg

    def namespaces(self) -> dict[str, list[Any]]:
        with self._lock:
            markers = list(self.last.markers) if self.last is not None else []
        out: dict[str, list[Any]] = {}
        for marker in markers:
            out.setdefault(marker.ns, []).append(marker)
        return out


@pytest.mark.usefixtures("gui_programs", "sim", "markers")
def test_rviz_shades_the_radio_coverage_and_marks_last_links(
    ros_master: RosMaster, tmp_path: Path
) -> None:
    if not rospy.core.is_initialized():
        rospy.init_node("rviz_coverage_test", anonymous=True, disable_signals=True)
    latest = LatestArray()
    layers = wait_until(
        lambda: (
            (n := latest.namespaces())
            and {"coverage_model", "last_link_label"} <= n.keys()
            and len(n["last_link_label"]) == len(ROBOTS)
            and n
        ),
        30.0,
        "the coverage layer with the model and every robot's last link",
    )
    [model] = layers["coverage_model"]
    # The covered cells of the 80 x 80 m site: the lander's 24 m, less what rocks shadow.
    assert 900 < len(model.points) == len(model.colors) < 3.2 * 24 * 24, len(model.points)
    labels = sorted(m.text for m in layers["last_link_label"])
    assert [LABEL.match(text)[1] for text in labels] == sorted(ROBOTS), labels  # type: ignore[index]

    tool = load_tool()
    background = tool.config_background(CONFIG)
    # The shading covers most of the view, which is then found by the window around it.
    check = tool.DrawnCheck(background=background, min_colors=100)
    output = tmp_path / "coverage.png"
    result = tool.take_screenshot(
        CONFIG, output, timeout=40.0, settle=3.0, check=check, env=ros_master.env,
        log=tmp_path / "rviz.log",
    )  # fmt: skip
    assert not result.problems, result.problems
    view = result.shot.view(background)
    assert view is not None
    px = view.pixels.astype(np.int16)
    height, width = px.shape[:2]
    # the window is the left 960 px of a 1600x1000 screen, the panels on its left
    assert width > 550 and height > 700, "the 3D view is small"
    inside = near(px, project((*COVERED, 0.0), width, height), 12)
    outside = near(px, project((*UNCOVERED, 0.0), width, height), 12)
    assert inside.size and outside.size, "both spots lie in the view"
    # Covered: the green channel leads (green to yellow); far out: the site, unshaded.
    assert (inside[..., 1] - inside[..., 2]).mean() > 25, inside.mean(axis=(0, 1))
    assert (outside[..., 1] - outside[..., 2]).mean() < 10, outside.mean(axis=(0, 1))
