#!/usr/bin/env python3
"""Take ``docs/rviz_coverage.png``: the operator's rviz showing radio coverage, headless.

Starts the simulated team like ``tools/rviz_operator_screenshot.py`` does (its
:func:`operator_launch`), gives the science rover the ``continue`` lost-link policy and
sends it beyond the lander's Wi-Fi to :data:`OUT_THERE`, and waits until it stands there
out of coverage and its last-link reading is :data:`AGE` sim seconds old. Meanwhile rviz
(``rviz/operator.rviz``) runs on a virtual screen; the picture shows the radio model's
shading, the rover's own readings along its way and its last-link mark with its age.

Run after ``source env.sh``::

    python tools/rviz_coverage_screenshot.py -o docs/rviz_coverage.png

Exit status: 0 written; 1 the rover did not get there or rviz did not draw in time (the
last screenshot is still written); 2 a program is missing or failed.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rviz_operator_screenshot as operator  # the sibling tool: the team, waiting
import rviz_screenshot as shots  # the sibling tool: Xvfb, rviz, grabbing

OUT_THERE = (4.0, 26.0)  # beyond the Mars lander's 24 m, in the config's first view (north)
AGE = 20.0  # sim seconds since the rover last had a link, in the picture
ROBOT = "science_rover"


def take(args: argparse.Namespace) -> int:
    """Start everything, send the rover out, screenshot; the exit status."""
    shots.require_programs("roslaunch", "Xvfb", "rviz", "import", "convert")
    port = operator.free_port()
    home = Path(tempfile.mkdtemp(prefix="rviz_coverage_"))
    os.environ.update(
        ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_IP="127.0.0.1", ROS_HOME=str(home)
    )
    os.environ.pop("ROS_HOSTNAME", None)
    import rosgraph
    import rospy

    from rosmc_server.core import LostLinkPolicy
    from rosmc_server.ros.client import ControlCommand, MissionClient, MissionWatch

    check = shots.DrawnCheck(background=shots.config_background(operator.CONFIG), min_colors=100)
    with contextlib.ExitStack() as stack:
        stack.enter_context(operator.operator_launch(port, home, args.real_time_factor))
        master = rosgraph.Master("/rviz_coverage_screenshot")
        operator.wait_for(master.is_online, "the ROS master", operator.START_TIMEOUT)
        rospy.init_node("rviz_coverage_screenshot", anonymous=True, disable_signals=True)
        stack.callback(rospy.signal_shutdown, "screenshot taken")
        watch = MissionWatch(events=False, states=True)
        states: dict[str, object] = {}

        def state() -> object:
            states.update(watch.take_agent_states() or {})
            return states.get(ROBOT)

        operator.wait_for(lambda: getattr(state(), "link", "") == "up", f"{ROBOT}'s link", 60.0)
        display = stack.enter_context(shots.virtual_screen(*args.size))
        env = shots.rviz_environment(display, os.environ)
        started = shots.drawn_rviz(operator.CONFIG, env, home / "rviz.log", check, attempts=3)
        rviz = stack.enter_context(started).process  # restarted if it dies at start-up
        client = MissionClient(timeout=30.0)
        stack.callback(client.close)
        client.get_mission()
        client.set_lost_link_policy(ROBOT, LostLinkPolicy())  # it stays out there
        x, y = OUT_THERE
        client.add_skill(ROBOT, "navigate_to", {"target": {"x": x, "y": y}, "speed": 1.0})
        client.synchronize(ROBOT)
        operator.wait_for(
            lambda: not any(s.transfer for s in client.fetch_mission().skills()),
            "the rover to store its skill",
            30.0,
        )
        client.control(ControlCommand.START, ROBOT)
        left: list[float] = []

        def pictured() -> bool:
            status = state()
            pose = getattr(status, "pose", None)
            if pose is None or math.dist((pose.x, pose.y), OUT_THERE) > 0.5:
                return False
            if getattr(status, "in_coverage", True):
                return False
            if not left:
                left.append(time.monotonic())
            return time.monotonic() - left[0] > AGE / args.real_time_factor

        deadline = time.monotonic() + args.timeout
        while True:
            if rviz.poll() is not None:
                raise shots.ScreenshotError(f"rviz exited ({rviz.returncode}); see {home}")
            shot = shots.grab(display)
            ready = pictured() and not check.problems(shot)
            if ready or time.monotonic() > deadline:
                break
            time.sleep(0.5)
        if ready:
            time.sleep(args.settle)
            shot = shots.grab(display)
        shot.write_png(args.output)
        if not ready:
            print(
                f"rviz_coverage_screenshot: not pictured in time; logs in {home}", file=sys.stderr
            )
            return 1
    shutil.rmtree(home, ignore_errors=True)
    print(f"rviz_coverage_screenshot: {args.output} written")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse the command line, take the screenshot, report."""
    parser = argparse.ArgumentParser(
        prog="rviz_coverage_screenshot",
        description="Screenshot rviz's radio coverage with a rover out of it (headless).",
    )
    parser.add_argument(
        "-o", "--output", type=Path, default=operator.REPO / "docs" / "rviz_coverage.png"
    )
    parser.add_argument("--real-time-factor", type=float, default=5.0, help="sim speed (5)")
    parser.add_argument("--timeout", type=float, default=180.0, help="wall seconds (180)")
    parser.add_argument("--settle", type=float, default=2.0, help="wall seconds (2)")
    parser.add_argument("--size", type=shots._size, default=shots.config_window(operator.CONFIG))
    args = parser.parse_args(argv)
    try:
        return take(args)
    except (shots.ScreenshotError, TimeoutError) as error:
        print(f"rviz_coverage_screenshot: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rviz_coverage_screenshot: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
