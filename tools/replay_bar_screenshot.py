#!/usr/bin/env python3
"""Take the docs' picture of a replay in the station (File > Open recording…).

Starts ``Xvfb`` (``--size``), a private rosmaster, the mission server, the marker node and the
operator's rviz (``rviz.launch``), opens the real command window beside rviz on the virtual
screen, opens ``--recording`` (the committed sample) as an operator does from the File
menu, clicks the tick of the first failed or successful skill after ``--at`` seconds on the
replay bar, waits until rviz shows the replay too, and writes the screenshot to
``--output`` (docs/command_gui_replay.png). Every process it started is stopped. Run after
``source env.sh``::

    python tools/replay_bar_screenshot.py -o docs/command_gui_replay.png

Exit status: 0 when written, 1 when the replay did not get there in time (a screenshot is
still written, to show why).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from bench.bench_server import ros_master  # noqa: E402
from tools.command_gui_screenshot import launch  # noqa: E402
from tools.rviz_screenshot import (  # noqa: E402
    grab,
    require_programs,
    rviz_environment,
    stop_group,
    virtual_screen,
)

TIMEOUT = 120.0  # wall seconds for each step (rviz and a replay start on a busy machine)


def main(argv: Sequence[str] | None = None) -> int:
    """Open the recording, move the replay to an event, take the picture; the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "-o", "--output", type=Path, default=REPO / "docs" / "command_gui_replay.png"
    )
    parser.add_argument("--recording", type=Path, default=REPO / "bags" / "samples" / "demo.mcap")
    parser.add_argument("--at", type=float, default=4.0, help="seconds into the recording")
    parser.add_argument("--size", default="1600x1000", help="screen WIDTHxHEIGHT")
    args = parser.parse_args(argv)
    require_programs("Xvfb", "import", "roslaunch")
    width, height = (int(v) for v in args.size.split("x"))
    with (
        tempfile.TemporaryDirectory(prefix="rosmc_shot_") as tmp,
        virtual_screen(width, height) as display,
        ros_master(Path(tmp)) as env,
    ):
        os.environ.update(env, DISPLAY=display, QT_QPA_PLATFORM="xcb")
        server_launch = str(REPO / "launch" / "mission_server.launch")
        server = launch(env, Path(tmp) / "server.log", server_launch, f"journal_dir:={tmp}")
        # One roslaunch after the other: launches started together on a new master each
        # declare their own run id, and all but the first end.
        node_up("/rosmc/mission_server")
        views = [launch(env, Path(tmp) / "markers.log", str(REPO / "launch" / "markers.launch"))]
        node_up("/rosmc/markers")
        rviz_launch = (str(REPO / "launch" / "rviz.launch"), "respawn:=true")
        views.append(launch(rviz_environment(display, env), Path(tmp) / "rviz.log", *rviz_launch))
        try:
            status = run(args, display, (width, height))
        finally:
            for process in (*views, server):
                stop_group(process, signal.SIGINT)
        if status:  # what the server said, to show why
            print((Path(tmp) / "server.log").read_text()[-3000:], file=sys.stderr)
        return status


def node_up(name: str) -> None:
    """Wait until the master (``ROS_MASTER_URI``) knows node ``name``."""
    import rosgraph

    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        try:
            rosgraph.Master("/shot").lookupNode(name)
            return
        except (rosgraph.MasterError, OSError):
            time.sleep(0.5)
    raise TimeoutError(f"{name} did not start")


def run(args: argparse.Namespace, display: str, size: tuple[int, int]) -> int:
    """Open the window and the recording, go to the event, take the picture."""
    import rosgraph
    import rospy
    from python_qt_binding.QtCore import QPoint, Qt
    from python_qt_binding.QtTest import QTest
    from python_qt_binding.QtWidgets import QApplication

    from rosmc_rqt_command.qt.station_menu import StationHooks, StationMenu
    from rosmc_rqt_command.replay_ticks import TickKind
    from rosmc_rqt_command.standalone import CommandWindow, build, join_station
    from rosmc_server.recording.history import MissionHistory
    from rosmc_server.ros.client import init_node

    app = QApplication.instance() or QApplication(["rosmc_command"])
    init_node("rosmc_replay_screenshot")
    widget, bridge = build()
    window = CommandWindow(widget, "ROSMC command")  # on its part of the screen
    menu = StationMenu(widget, StationHooks(str, lambda: (None, "")), window.close)
    station = join_station(widget, menu)
    window.show()

    def rviz_on(prefix: str) -> bool:
        _pubs, subscribers, _srvs = rosgraph.Master("/shot").getSystemState()
        topic = f"{prefix}/rosmc/markers/update"
        return any(t == topic and "/rviz_operator_view" in n for t, n in subscribers)

    def wait(condition: Callable[[], object], what: str) -> None:
        deadline = time.monotonic() + TIMEOUT
        while not condition():
            if time.monotonic() > deadline:
                raise TimeoutError(f"timed out waiting until {what}")
            QTest.qWait(100)

    status = 1
    bar = widget.replay.bar
    try:
        wait(lambda: widget.view.loaded, "the live mission is shown")
        wait(lambda: rviz_on(""), "rviz shows the live mission")
        widget.replay.open(str(args.recording))
        wait(lambda: bar.play_button.isEnabled(), "the replay answers")
        outcomes = (TickKind.SUCCESS, TickKind.FAILURE)
        tick = next(t for t in bar.slider.ticks if t.kind in outcomes and t.time >= args.at)
        point = QPoint(bar.slider.x_of(tick.time), 6)
        QTest.mouseClick(bar.slider, Qt.LeftButton, Qt.NoModifier, point)
        there = f"the replay at {tick.text}"
        wait(lambda: bar.shown and bar.shown.status.position == tick.time, there)
        revision = MissionHistory.from_journal(args.recording).revision_at(tick.time).revision
        wait(lambda: widget.view.revision == revision, f"the mission at r{revision}")
        wait(lambda: widget.view.statuses, "the robots reported")
        agent = next(a for a, v in widget.view.agents.items() if v.skills)
        widget.tasks.select_ids([widget.view.view(agent).skills[0].id])
        wait(lambda: rviz_on("/replay"), "rviz shows the replay")
        QTest.qWait(8000)  # rviz has drawn the replay's robots and markers
        status = 0
    except (TimeoutError, StopIteration) as error:
        print(f"replay_bar_screenshot: {error!r}", file=sys.stderr)
    finally:
        QTest.qWait(1500)
        grab(display).write_png(args.output)
        print(f"wrote {args.output}")
        widget.replay.close()
        station.close()
        bridge.close()
        window.close()
        app.processEvents()
        rospy.signal_shutdown("screenshot taken")
    return status


if __name__ == "__main__":
    sys.exit(main())
