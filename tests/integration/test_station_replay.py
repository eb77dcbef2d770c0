"""Open recording… in the command window shows the replay in rviz too; Return to live, live.

A real master, mission server and live marker node; real rviz started by ``rviz.launch``
(``rviz_station``) under Xvfb; the real command window (offscreen Qt) joined to the station
as the standalone window is. The recording is opened with the mouse (File > Open
recording…, the path typed into the dialog): rviz is started again on the replay's topics
and the replay's marker node shows the replayed time; *Return to live* puts rviz back on the
live topics. The window's clock shows the replayed time and then the live clock again.
rviz killed with SIGKILL comes back (``respawn``) on the live topics. A replay that is
killed while rviz follows it (as a crashed window takes its replay along) sends rviz back to
the live topics by itself.
"""

from __future__ import annotations

import os
import re
import signal
import sys
import xmlrpc.client
from collections.abc import Iterator
from typing import Any

import pytest
import rosgraph
import rospy
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtTest import QTest
from python_qt_binding.QtWidgets import QApplication

from rosmc_rqt_command.qt.station_menu import StationHooks, StationMenu
from rosmc_rqt_command.standalone import join_station
from rosmc_rviz_markers.ros.rviz_window import replay_running
from rosmc_server import interface
from tests.conftest import LaunchProcess, RosMaster
from tests.integration.server_fixtures import REPO, StartServer
from tests.integration.test_command_gui_server import Window, answer_file_dialog, shown
from tests.integration.test_command_gui_server import wait_until as qt_wait
from tests.integration.test_rviz import gui_programs, load_tool  # noqa: F401
from tests.ros.recording_checks import SAMPLE

pytest_plugins = ["tests.integration.server_fixtures"]

START = 120.0  # rviz under software OpenGL and a replay, on a busy machine
VIEW = "/rviz_operator_view"  # the rviz that rviz_station runs


def subscribed(node: str) -> set[str]:
    """The topics ``node`` subscribes to now."""
    _pubs, subscribers, _services = rosgraph.Master("/station_test").getSystemState()
    return {topic for topic, nodes in subscribers if node in nodes}


def subscribers_of(topic: str) -> set[str]:
    """The nodes that subscribe to ``topic`` now."""
    _pubs, subscribers, _services = rosgraph.Master("/station_test").getSystemState()
    return {node for name, nodes in subscribers if name == topic for node in nodes}


def view_pid() -> int | None:
    """The process id of the rviz that rviz_station runs (None while there is none)."""
    try:
        uri = rosgraph.Master("/station_test").lookupNode(VIEW)
        return int(xmlrpc.client.ServerProxy(uri).getPid("/station_test")[2])
    except (rosgraph.MasterError, OSError, xmlrpc.client.Error):
        return None


def station_text(prefix: str) -> str | None:
    """The mission clock's text as the marker node under ``prefix`` publishes it."""
    topic = f"{prefix}/rosmc/markers/clock"
    try:
        clock = rospy.wait_for_message(topic, MarkerArray, timeout=5.0)
    except rospy.ROSException:
        return None
    return str(clock.markers[0].text) if clock.markers else None


@pytest.fixture
def rviz(
    ros_master: RosMaster, launch_process: LaunchProcess, start_server: StartServer
) -> Iterator[None]:
    """A server, the live marker node and the operator's rviz on a virtual screen."""
    start_server()
    launch_process(["roslaunch", "rosmc", "markers.launch"], env=ros_master.env, name="markers")
    # one roslaunch after the other: two starting together on a new master clash on its run id
    qt_wait(lambda: "/rosmc/markers" in subscribers_of("/rosmc/markers/feedback"), START, "markers")
    tool = load_tool()
    with tool.virtual_screen(1600, 1000) as display:
        env = tool.rviz_environment(display, ros_master.env)
        # respawn as in operator.launch: rviz under software OpenGL now and then dies at start-up
        launch = ["roslaunch", "rosmc", "rviz.launch", "respawn:=true"]
        launch_process(launch, env=env, name="rviz")
        qt_wait(lambda: "/rosmc/markers/update" in subscribed(VIEW), START, "rviz on live")
        yield


@pytest.fixture
def window(client_node: Any) -> Iterator[tuple[Window, StationMenu]]:
    """The command window joined to the station, as the standalone window joins it."""
    app = QApplication.instance() or QApplication([])
    opened = Window()
    menu = StationMenu(opened.w, StationHooks(str, lambda: (None, "")), opened.w.close)
    station = join_station(opened.w, menu)
    yield opened, menu
    opened.widget.replay.close()
    station.close()
    opened.close()
    app.processEvents()


def on_live() -> bool:
    """rviz is on the live mission's topics (and on no replay's)."""
    topics = subscribed(VIEW)
    return "/rosmc/markers/update" in topics and not any("replay" in t for t in topics)


def seconds(text: str | None) -> int | None:
    """The seconds a clock text shows (None if it shows none)."""
    found = re.search(r"(\d+):(\d\d):(\d\d)$", text or "")
    if found is None:
        return None
    hours, minutes, secs = map(int, found.groups())
    return hours * 3600 + minutes * 60 + secs


@pytest.mark.usefixtures("gui_programs", "rviz")
def test_open_recording_shows_the_replay_in_rviz_and_return_to_live_brings_it_back(
    window: tuple[Window, StationMenu],
) -> None:
    opened, menu = window
    shown(opened)
    widget, mode = opened.w, opened.w.replay
    live_view = subscribed(VIEW)
    assert "/rosmc/markers/update" in live_view and "/tf" in live_view
    assert menu.clock.text().startswith("UTC "), menu.clock.text()  # no simulation: UTC

    # File > Open recording…, the sample chosen in the dialog.
    answer_file_dialog(str(SAMPLE))
    mode.open_action.trigger()
    bar = mode.bar
    qt_wait(lambda: bar.isVisible() and bar.play_button.isEnabled(), START, "the replay bar")

    # rviz is on the replay's topics now (and no longer on the live ones)...
    def on_replay() -> bool:
        topics = subscribed(VIEW)
        return "/replay/rosmc/markers/update" in topics and "/replay/tf" in topics

    qt_wait(on_replay, START, "rviz on the replay's topics")
    assert "/rosmc/markers/update" not in subscribed(VIEW)
    # ... where the replay's marker node shows the replayed time over the lander.
    text = qt_wait(lambda: station_text("/replay"), START, "the replay's clock")
    assert text.startswith("replay time "), text
    assert menu.clock.text().startswith("replay time "), menu.clock.text()

    # Play: the replayed time advances, in the window's header and in rviz.
    first = seconds(menu.clock.text())
    QTest.mouseClick(bar.play_button, Qt.LeftButton)
    qt_wait(lambda: (seconds(menu.clock.text()) or 0) > (first or 0), 60, "the clock on")
    qt_wait(lambda: (seconds(station_text("/replay")) or 0) > (first or 0), 60, "rviz's clock on")

    # Return to live: rviz on the live topics again, the replay's processes gone.
    QTest.mouseClick(bar.live_button, Qt.LeftButton)

    qt_wait(on_live, START, "rviz on the live topics")
    assert not widget.backend.read_only
    qt_wait(lambda: menu.clock.text().startswith("UTC "), 10, "the live clock again")
    assert station_text("")  # the live marker node's clock is still there

    # rviz killed (-9): roslaunch's respawn starts it again, on the live mission.
    first = view_pid()
    assert first is not None
    os.kill(first, signal.SIGKILL)
    qt_wait(lambda: view_pid() not in (None, first), START, "rviz back")
    qt_wait(on_live, START, "rviz back on the live topics")


@pytest.mark.usefixtures("gui_programs", "rviz")
def test_rviz_returns_to_live_when_the_replay_it_follows_is_gone(
    ros_master: RosMaster, launch_process: LaunchProcess
) -> None:
    """A replay that ends without a word (its window crashed, taking it along): rviz goes live."""
    prefix = "/replay_gone"
    rosmc = [sys.executable, str(REPO / "scripts" / "rosmc")]
    replay = launch_process(
        [*rosmc, "replay", str(SAMPLE), "--prefix", prefix, "--paused", "--hold"],
        env=ros_master.env,
        name="replay",
    )
    qt_wait(lambda: replay_running(prefix), START, "the replay running")
    source = rospy.Publisher(interface.VIEW_SOURCE_TOPIC, String, queue_size=1, latch=True)
    try:
        source.publish(String(data=prefix))  # what the window said, and never takes back
        update = f"{prefix}/rosmc/markers/update"
        qt_wait(lambda: update in subscribed(VIEW), START, "rviz on the replay's topics")

        os.kill(replay.pid, signal.SIGKILL)  # nothing unregistered: the master still lists it

        qt_wait(on_live, START, "rviz back on the live topics")
    finally:
        source.unregister()
