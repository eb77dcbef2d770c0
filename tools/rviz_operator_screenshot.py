#!/usr/bin/env python3
"""Retake ``docs/rviz.png``: the operator's rviz in the middle of a mission, headless.

Starts ``roslaunch rosmc operator.launch sim:=true`` (mission server, simulated team,
marker node; no rviz, no command GUI) on a private ROS master on a free port, with the
journal in a temporary directory. Then plans and starts a small mission through
:class:`~rosmc_server.ros.client.MissionClient`, so that at the moment of the picture

* the drone flies over the *Survey area* (``fly_over`` running: a green area),
* the science rover has reached *Outcrop view* (``navigate_to`` done: a teal flag) and
  waits at a barrier for the manipulator rover to identify stones at *Sample site*
  together (an amber flag),
* the manipulator rover has picked the Wi-Fi box at the lander and carries it to
  *Wi-Fi spot* (``place_box`` running: a green flag), the barrier's partner skill at
  *Sample site* synchronized after it, and a blueprint skill at *Stone B* (not
  synchronized: a blue flag),

meanwhile rviz (``rviz/operator.rviz``) runs on a virtual screen (``tools/rviz_screenshot.py``).
With ``--out-of-contact AGENT`` that robot then falls silent (``tools/out_of_contact.py``) and,
once its link is down, its blueprint and a new lost-link policy wait for contact: its icon
says ``LINK DOWN .. s, 2 WAITING .. s``.
When the mission is in that state and rviz has drawn, it waits ``--settle`` seconds and
writes the screenshot. Everything it started is stopped by process group at the end, also
on Ctrl-C or SIGTERM.

With ``--first-look`` it screenshots rviz as it opens instead (the team at the lander, no
mission yet). The screen is as large as the config's window (900x1000: the left part of a
1600x1000 screen beside the command GUI) unless ``--size`` says otherwise.

Run after ``source env.sh``::

    python tools/rviz_operator_screenshot.py -o docs/rviz.png
    python tools/rviz_operator_screenshot.py --first-look -o docs/rviz_first_look.png

Exit status: 0 written; 1 the mission did not reach that state or rviz did not draw in
``--timeout`` (the last screenshot is still written, to show why); 2 a program is missing
or failed.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import xmlrpc.client
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import out_of_contact
import rviz_screenshot as shots  # the sibling tool: Xvfb, rviz, grabbing

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "rviz" / "operator.rviz"
START_TIMEOUT = 60.0

SURVEY = ((9.0, 3.0), (21.0, 3.0), (21.0, 13.0), (9.0, 13.0))
OUTCROP_VIEW = (8.0, -3.0, 0.4)  # x, y, yaw of the science rover's first stop
SAMPLE_SITE = (12.0, -8.0)
WIFI_SPOT = (0.5, -10.5, -0.6)
AWAY_FROM_LANDER = 4.5  # the manipulator rover, in the picture (m)
STONE_B = (18.0, -5.0)


def free_port() -> int:
    """A free TCP port on the loopback interface."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def wait_for(condition: Callable[[], object], what: str, timeout: float) -> None:
    """Poll ``condition`` until it is true; ``TimeoutError`` naming ``what`` after ``timeout``."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out waiting for {what}")
        time.sleep(0.2)


@contextlib.contextmanager
def operator_launch(port: int, home: Path, real_time_factor: float) -> Iterator[Path]:
    """``operator.launch sim:=true`` without GUIs on a master at ``port``; yields its log."""
    log = home / "roslaunch.log"
    command = [
        "roslaunch",
        "-p",
        str(port),
        "rosmc",
        "operator.launch",
        "sim:=true",
        "rviz:=false",
        "command_gui:=false",
        f"real_time_factor:={real_time_factor}",
        f"journal_dir:={home}",
    ]
    with log.open("wb") as out:
        process = subprocess.Popen(
            command,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:
        yield log
    finally:
        shots.stop_group(process, signal.SIGINT)


def plan_mission(client: object) -> dict[str, str]:
    """Plan and start the pictured mission; the ids of the skills the picture waits for."""
    from rosmc_server.core import MarkerType, Pose, TaskMarker
    from rosmc_server.ros.client import ControlCommand, MissionClient

    assert isinstance(client, MissionClient)
    client.get_mission()
    area = tuple(Pose(x, y) for x, y in SURVEY)
    client.add_task_marker(TaskMarker("Survey area", MarkerType.AREA, Pose(), area))
    x, y, yaw = OUTCROP_VIEW
    client.add_task_marker(TaskMarker("Outcrop view", MarkerType.POSE, Pose(x, y, yaw=yaw)))
    client.add_task_marker(TaskMarker("Sample site", MarkerType.POSITION, Pose(*SAMPLE_SITE)))
    x, y, yaw = WIFI_SPOT
    client.add_task_marker(TaskMarker("Wi-Fi spot", MarkerType.POSE, Pose(x, y, yaw=yaw)))
    client.add_task_marker(TaskMarker("Stone B", MarkerType.POSITION, Pose(*STONE_B)))
    ids = {}
    client.add_skill("drone", "take_off", {"altitude": 6.0})
    ids["survey"] = client.add_skill(
        "drone", "fly_over", {"altitude": 6.0, "spacing": 1.0}, bindings={"area": "Survey area"}
    ).skill_id
    ids["outcrop"] = client.add_skill(
        "science_rover", "navigate_to", bindings={"target": "Outcrop view"}
    ).skill_id
    ids["identify"] = client.add_skill(
        "science_rover", "identify_stones", bindings={"position": "Sample site"}
    ).skill_id
    ids["pick_box"] = client.add_skill(
        "manipulator_rover", "pick_box", {"box": "wifi_box"}
    ).skill_id
    ids["place_box"] = client.add_skill(
        "manipulator_rover", "place_box", bindings={"target": "Wi-Fi spot"}
    ).skill_id
    partner = client.add_skill(
        "manipulator_rover", "identify_stones", bindings={"position": "Sample site"}
    ).skill_id
    client.add_barrier([ids["identify"], partner])
    for agent in ("drone", "science_rover", "manipulator_rover"):
        client.synchronize(agent)
    wait_for(
        lambda: not any(s.transfer for s in client.fetch_mission().skills()),
        "the robots to store their skills",
        30.0,
    )
    client.control(ControlCommand.START)
    ids["blueprint"] = client.add_skill(
        "manipulator_rover", "pick_stone", bindings={"position": "Stone B"}
    ).skill_id
    return ids


def missing(client: object, ids: dict[str, str], manipulator: tuple[float, float] | None) -> str:
    """What the mission still lacks of the pictured state ("" when it is there).

    ``manipulator``: where the manipulator rover is (x, y), if known.
    """
    from rosmc_server.core import SkillStatus
    from rosmc_server.ros.client import MissionClient

    assert isinstance(client, MissionClient)
    state = client.fetch_mission()
    status = {key: state.skill(skill_id).status for key, skill_id in ids.items()}
    wanted = {
        "survey": SkillStatus.RUNNING,
        "outcrop": SkillStatus.SUCCESS,
        "identify": SkillStatus.SYNCWAITING,
        "place_box": SkillStatus.RUNNING,
        "blueprint": SkillStatus.IDLE,
    }
    lacking = [f"{key} {status[key].name}" for key, want in wanted.items() if status[key] != want]
    if manipulator is None or math.hypot(*manipulator) < AWAY_FROM_LANDER:
        lacking.append(f"manipulator_rover at {manipulator}")
    return ", ".join(lacking)


def take(args: argparse.Namespace) -> int:
    """Start everything, drive the mission, screenshot; the exit status."""
    shots.require_programs("roslaunch", "Xvfb", "rviz", "import", "convert")
    port = free_port()
    home = Path(tempfile.mkdtemp(prefix="rviz_operator_"))
    os.environ.update(
        ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_IP="127.0.0.1", ROS_HOME=str(home)
    )
    os.environ.pop("ROS_HOSTNAME", None)
    import rosgraph
    import rospy

    from rosmc_server.ros.client import MissionClient, MissionWatch

    config = CONFIG
    background = shots.config_background(CONFIG)
    check = shots.DrawnCheck(background=background, min_colors=100)
    with contextlib.ExitStack() as stack:
        launch_log = stack.enter_context(operator_launch(port, home, args.real_time_factor))
        master = rosgraph.Master("/rviz_operator_screenshot")
        wait_for(master.is_online, "the ROS master", START_TIMEOUT)
        rospy.init_node("rviz_operator_screenshot", anonymous=True, disable_signals=True)
        stack.callback(rospy.signal_shutdown, "screenshot taken")
        watch = MissionWatch(events=False, states=True)

        def links_up() -> bool:
            states = watch.take_agent_states() or {}
            return len(states) == 3 and all(s.link == "up" for s in states.values())

        try:
            wait_for(links_up, "every robot link to come up", START_TIMEOUT)
        except TimeoutError:
            print(launch_log.read_text(errors="replace")[-3000:], file=sys.stderr)
            raise
        if args.view:
            config = shots.with_saved_view(CONFIG, args.view, home)
        display = stack.enter_context(shots.virtual_screen(*args.size))
        env = shots.rviz_environment(display, os.environ)
        started = shots.drawn_rviz(config, env, home / "rviz.log", check, attempts=3)
        rviz = stack.enter_context(started).process  # restarted if it dies at start-up
        client = MissionClient(timeout=30.0)
        stack.callback(client.close)
        if args.first_look:
            return first_look(args, display, check, home)
        ids = plan_mission(client)
        print("rviz_operator_screenshot: mission started; waiting for the pictured state")
        deadline = time.monotonic() + args.timeout
        shot = shots.grab(display)
        states: dict[str, Any] = {}

        def pictured() -> bool:
            states.update(watch.take_agent_states() or {})
            pose = getattr(states.get("manipulator_rover"), "pose", None)
            lacking = missing(client, ids, None if pose is None else (pose.x, pose.y))
            if lacking and args.verbose:
                print(f"rviz_operator_screenshot: not yet: {lacking}", flush=True)
            return not lacking

        while True:
            if rviz.poll() is not None:
                raise shots.ScreenshotError(f"rviz exited ({rviz.returncode}); see {home}")
            shot = shots.grab(display)
            ready = pictured() and not check.problems(shot)
            if ready or time.monotonic() > deadline:
                break
            time.sleep(0.5)
        if ready and args.out_of_contact:
            silenced = out_of_contact.silence_executor(args.out_of_contact, "/rviz_operator_shot")
            stack.callback(out_of_contact.resume_executor, silenced)
            waiting_for_contact(watch, client, args.out_of_contact)
        if ready and args.restart_server:
            restart_server()
        if ready:
            time.sleep(args.settle)  # rviz draws the last updates; the state lasts minutes
            shot = shots.grab(display)
            ready = pictured()
        shot.write_png(args.output)
        if not ready:
            print(
                f"rviz_operator_screenshot: not in the pictured state after {args.timeout:g} s "
                f"({'; '.join(check.problems(shot)) or 'mission'}); last screenshot in "
                f"{args.output}; logs in {home}",
                file=sys.stderr,
            )
            return 1
    shutil.rmtree(home, ignore_errors=True)  # kept (logs) only when something went wrong
    print(f"rviz_operator_screenshot: {args.output} written")
    return 0


def first_look(args: argparse.Namespace, display: str, check: Any, home: Path) -> int:
    """The screenshot of rviz as it opens: the team at the lander, no mission yet."""
    deadline = time.monotonic() + args.timeout
    while check.problems(shot := shots.grab(display)) and time.monotonic() < deadline:
        time.sleep(0.5)
    time.sleep(args.settle)  # the markers' full update, TF and the site arrive
    shot = shots.grab(display)
    shot.write_png(args.output)
    problems = check.problems(shot)
    if problems:
        print(
            f"rviz_operator_screenshot: rviz did not draw ({'; '.join(problems)})", file=sys.stderr
        )
        return 1
    shutil.rmtree(home, ignore_errors=True)
    print(f"rviz_operator_screenshot: {args.output} written (first look)")
    return 0


def waiting_for_contact(watch: Any, client: object, agent: str) -> None:
    """Once ``agent``'s link is down, send it work; return when the server shows it waiting."""
    states: dict[str, Any] = {}

    def shown(test: Callable[[Any], bool]) -> bool:
        states.update(watch.take_agent_states() or {})
        return agent in states and test(states[agent])

    wait_for(lambda: shown(lambda s: s.link == "down"), f"{agent}'s link down", 30.0)
    out_of_contact.send_waiting_work(client, agent)
    wait_for(lambda: shown(lambda s: s.commands_waiting >= 2), f"work waiting for {agent}", 30.0)


def server_pid() -> int | None:
    """The mission server's process id (None while it is not registered or not answering)."""
    import rosgraph

    from rosmc_server.interface import SERVER_NODE

    master = rosgraph.Master("/rviz_operator_shot")
    try:
        pid = xmlrpc.client.ServerProxy(master.lookupNode(SERVER_NODE)).getPid("/shot")[2]
    except (rosgraph.MasterException, OSError, xmlrpc.client.Error):
        return None
    return int(pid)


def restart_server() -> None:
    """kill -9 the mission server; return once roslaunch started it again and it serves."""
    first = server_pid()
    if first is None:
        raise shots.ScreenshotError("the mission server is not running")
    os.kill(first, signal.SIGKILL)
    wait_for(lambda: server_pid() not in (None, first), "the mission server back", 60.0)
    print("rviz_operator_screenshot: mission server killed (-9) and restarted by roslaunch")


def _raise_keyboard_interrupt(_signum: int, _frame: object) -> None:
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse the command line, take the screenshot, report."""
    parser = argparse.ArgumentParser(
        prog="rviz_operator_screenshot",
        description="Screenshot the operator's rviz mid-mission (headless; private master).",
    )
    parser.add_argument("-o", "--output", type=Path, default=REPO / "docs" / "rviz.png")
    parser.add_argument("--real-time-factor", type=float, default=1.0, help="sim speed (1)")
    parser.add_argument("--timeout", type=float, default=180.0, help="wall seconds (180)")
    parser.add_argument("--settle", type=float, default=3.0, help="wall seconds (3)")
    parser.add_argument(
        "--size",
        type=shots._size,
        default=shots.config_window(CONFIG),
        help="screen size (default: the config's window, 900x1000)",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="say what is missing")
    parser.add_argument(
        "--first-look", action="store_true", help="rviz as it opens: the team, no mission"
    )
    parser.add_argument("--view", help="a saved view of operator.rviz (default: its current)")
    parser.add_argument("--out-of-contact", default="", help="a robot cut off, work waiting")
    parser.add_argument(
        "--restart-server", action="store_true", help="kill -9 the server first (it comes back)"
    )
    args = parser.parse_args(argv)
    signal.signal(signal.SIGTERM, _raise_keyboard_interrupt)
    try:
        return take(args)
    except (shots.ScreenshotError, TimeoutError) as error:
        print(f"rviz_operator_screenshot: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rviz_operator_screenshot: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
