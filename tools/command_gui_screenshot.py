#!/usr/bin/env python3
"""Take the docs' picture of the command GUI: a staged, simulated mission under Xvfb.

Starts ``Xvfb`` (``--size``, 1600x1000), a private rosmaster, the mission server and the
simulated team (``roslaunch rosmc mission_server.launch`` and ``sim.launch``), opens the
real command window on the virtual screen (filling it), and plays the operator through
the operator client so that, when the picture is taken,

* the drone has taken off and flown out (done), and waits at barrier B1 for the science
  rover ("waiting on science_rover");
* the science rover drove out (done) and is paused while exploring;
* the manipulator rover fetched the Wi-Fi box (done) and failed to identify stones at a
  region nobody has explored yet (the reason shows in the parameter panel);
* each robot has skills on board (on robot) and planned in its blueprint.

With ``--out-of-contact AGENT`` that robot's executor then falls silent (SIGSTOP, as a robot
out of radio range; SIGCONT after the picture), and once the server calls its link down the
operator sends the rest of its blueprint and a new lost-link policy: both wait for contact
(its header and rows say so). Then it selects the failed skill, waits
``--settle`` seconds, and writes the screenshot (``import -window root``) to ``--output``
(docs/command_gui.png). Every process it started is stopped, also on failure. Run after
``source env.sh``::

    python tools/command_gui_screenshot.py -o docs/command_gui.png
    python tools/command_gui_screenshot.py --out-of-contact manipulator_rover \
        -o docs/command_gui_waiting.png

Exit status: 0 when written, 1 when the mission did not reach the staged state in time
(a screenshot is still written, to show why).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from bench.bench_server import ros_master  # noqa: E402
from tools.out_of_contact import resume_executor, send_waiting_work, silence_executor  # noqa: E402
from tools.rviz_screenshot import grab, require_programs, stop_group, virtual_screen  # noqa: E402

STAGE_TIMEOUT = 120.0  # wall seconds for the mission to reach the staged state


def main(argv: Sequence[str] | None = None) -> int:
    """Stage the mission and take the picture; the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=REPO / "docs" / "command_gui.png")
    parser.add_argument("--size", default="1600x1000", help="screen WIDTHxHEIGHT")
    parser.add_argument("--settle", type=float, default=2.0, help="seconds before the shot")
    parser.add_argument("--rate", type=float, default=4.0, help="simulation real-time factor")
    parser.add_argument("--out-of-contact", default="", help="a robot cut off, work waiting")
    args = parser.parse_args(argv)
    require_programs("Xvfb", "import", "roslaunch")
    width, height = (int(v) for v in args.size.split("x"))
    with (
        tempfile.TemporaryDirectory(prefix="rosmc_shot_") as tmp,
        virtual_screen(width, height) as display,
        ros_master(Path(tmp)) as env,
    ):
        os.environ.update(DISPLAY=display, QT_QPA_PLATFORM="xcb")
        launches: list[subprocess.Popen[bytes]] = []
        try:
            return run(args, env, Path(tmp), launches, display)
        finally:
            for process in reversed(launches):
                stop_group(process, signal.SIGINT)


def launch(env: dict[str, str], log: Path, *args: str) -> subprocess.Popen[bytes]:
    """``roslaunch ARGS`` in its own process group, logging to ``log``."""
    with log.open("wb") as out:
        return subprocess.Popen(
            ["roslaunch", *args],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )


def run(
    args: argparse.Namespace,
    env: dict[str, str],
    work: Path,
    launches: list[subprocess.Popen[bytes]],
    display: str,
) -> int:
    """Start everything, stage the mission, take the picture."""
    import rospy
    from python_qt_binding.QtTest import QTest
    from python_qt_binding.QtWidgets import QApplication

    from rosmc_rqt_command.core.legality import RobotAction
    from rosmc_rqt_command.standalone import CommandWindow, build
    from rosmc_server.core import SkillStatus
    from rosmc_server.ros.client import MissionClient, init_node

    S = SkillStatus  # noqa: N806
    app = QApplication.instance() or QApplication(["rosmc_command"])
    init_node("rosmc_command_screenshot")  # before sim.launch sets /use_sim_time: wall clock
    # One roslaunch for both (two would fight over the master's run_id).
    launches.append(
        launch(
            env,
            work / "launch.log",
            str(REPO / "launch" / "mission_server.launch"),
            str(REPO / "launch" / "sim.launch"),
            f"journal_dir:={work}",
            f"real_time_factor:={args.rate}",
        )
    )

    def wait(condition: Callable[[], object], what: str, timeout: float = STAGE_TIMEOUT) -> None:
        deadline = time.monotonic() + timeout
        while not condition():
            if time.monotonic() > deadline:
                raise TimeoutError(f"timed out waiting until {what}")
            QTest.qWait(100)

    client = MissionClient(10.0)
    widget, bridge = build(timeout=5.0)
    window = CommandWindow(widget, "ROSMC command")
    screen = app.primaryScreen().geometry()
    window.setGeometry(screen)  # no window manager here: fill the screen exactly
    window.show()
    status = 1
    silenced = 0
    try:
        wait(lambda: widget.view.loaded and widget.view.library, "the window shows the mission")
        wait(lambda: _answers(client), "the mission server answers", 60)
        ids = stage(client, wait)
        mission = client.get_mission
        start_all = widget.actions_.all_robots[RobotAction.START]
        try:
            wait(start_all.isEnabled, "Start all can be pressed", 15)
        except TimeoutError:
            states = {a: s.executor_state for a, s in widget.view.statuses.items()}
            raise TimeoutError(f"Start all stays disabled; robots report {states}") from None
        start_all.trigger()  # the operator presses "Start all"
        wait(lambda: mission().skill(ids["explore"]).status is S.RUNNING, "the rover explores")
        widget.do_robot("science_rover", RobotAction.PAUSE)  # and the rover's pause button
        wait(lambda: mission().skill(ids["explore"]).status is S.PAUSED, "the rover paused")
        wait(lambda: mission().skill(ids["film"]).status is S.SYNCWAITING, "the drone waits")
        wait(lambda: mission().skill(ids["identify"]).status is S.FAILURE, "the failure")
        wait(
            lambda: all(
                (s := widget.view.skill(i)) is not None and s == mission().skill(i)
                for i in ids.values()
            ),
            "the window shows it all",
            20,
        )
        if args.out_of_contact:
            silenced = cut_off(client, widget, args.out_of_contact, wait)
        widget.tasks.select_ids([ids["identify"]])
        status = 0
    except TimeoutError as error:
        print(f"command_gui_screenshot: {error}", file=sys.stderr)
        for log in sorted(work.glob("*.log")):
            tail = log.read_text(errors="replace").splitlines()[-15:]
            print(f"--- {log.name}\n" + "\n".join(tail), file=sys.stderr)
    finally:
        QTest.qWait(int(args.settle * 1000))
        grab(display).write_png(args.output)
        print(f"wrote {args.output}")
        resume_executor(silenced)
        bridge.close()
        widget.files.ask = lambda _doing: "discard"  # the staged mission is not kept
        window.close()
        client.close()
        app.processEvents()
        rospy.signal_shutdown("screenshot taken")
    return status


def cut_off(client: object, widget: object, agent: str, wait: Callable[..., None]) -> int:
    """Silence ``agent``; once its link is down, send it work that then waits; its pid."""
    statuses = widget.view.statuses  # type: ignore[attr-defined]
    pid = silence_executor(agent, "/rosmc_command_screenshot")
    wait(lambda: (s := statuses.get(agent)) is not None and s.link == "down", f"{agent} down", 30)
    send_waiting_work(client, agent)
    wait(lambda: statuses[agent].commands_waiting >= 2, f"work waiting for {agent}", 30)
    return pid


def _answers(client: object) -> bool:
    from rosmc_server.core import RosmcError

    try:
        client.get_mission()  # type: ignore[attr-defined]
    except RosmcError:
        return False
    return True


def stage(client: object, wait: Callable[..., None]) -> dict[str, str]:
    """Plan, synchronize and start the mission; the ids of the skills to watch."""
    from rosmc_server.core import LostLinkKind, LostLinkPolicy
    from rosmc_server.ros.client import MissionClient

    assert isinstance(client, MissionClient)
    add = client.add_skill
    ids: dict[str, str] = {}
    # The drone flies out and films the rovers at RSS A together with the science rover.
    add("drone", "take_off", {"altitude": 8.0}, label="take off")
    add("drone", "navigate_to", {"target": {"x": 12.0, "y": 4.0}}, label="fly to RSS A")
    ids["film"] = add(
        "drone", "navigate_to", {"target": {"x": 15.0, "y": 6.0}}, label="film the rovers"
    ).skill_id
    drone_last = add("drone", "return_to_lander", label="back to the lander").skill_id
    add("drone", "land", label="land")
    add("drone", "recharge", {"level": 1.0}, label="recharge")
    # The science rover drives out, explores the plain, then identifies RSS A's stones.
    add("science_rover", "navigate_to", {"target": {"x": 6.0, "y": 1.0}}, label="drive east")
    plain = [
        {"x": 6.0, "y": 0.0},
        {"x": 14.0, "y": 0.0},
        {"x": 14.0, "y": 5.0},
        {"x": 6.0, "y": 5.0},
    ]
    ids["explore"] = add(
        "science_rover", "explore", {"area": plain}, label="explore the plain"
    ).skill_id
    ids["partner"] = add(
        "science_rover",
        "identify_stones",
        {"position": {"x": 16.0, "y": 9.0}, "mode": "detailed"},
        label="identify RSS A",
    ).skill_id
    science_last = add("science_rover", "return_to_lander", label="back to the lander").skill_id
    add("science_rover", "recharge", {"level": 1.0}, label="recharge")
    # The manipulator fetches the Wi-Fi box, then tries RSS B before anyone explored it.
    add("manipulator_rover", "pick_box", {"box": "wifi_box"}, label="fetch the Wi-Fi box")
    ids["identify"] = add(
        "manipulator_rover",
        "identify_stones",
        {"position": {"x": 30.0, "y": -16.0}},
        label="identify RSS B",
    ).skill_id
    add(
        "manipulator_rover",
        "pick_stone",
        {"position": {"x": 30.0, "y": -16.0}},
        label="pick a stone",
    )
    manipulator_last = add("manipulator_rover", "deposit_at_lander", label="bring it home").skill_id
    add("manipulator_rover", "return_to_lander", label="back to the lander")
    client.add_barrier([ids["film"], ids["partner"]])
    client.set_lost_link_policy("science_rover", LostLinkPolicy(LostLinkKind.HOLD, 30.0))
    client.set_lost_link_policy(
        "drone", LostLinkPolicy(LostLinkKind.SAFE_SKILL, 20.0, "return_to_lander")
    )
    for agent, last in (
        ("drone", drone_last),
        ("science_rover", science_last),
        ("manipulator_rover", manipulator_last),
    ):
        client.synchronize(agent, last)
    wait(
        lambda: all(
            client.get_mission().skill(i).status is not None
            and not client.get_mission().skill(i).is_editable
            for i in (drone_last, science_last, manipulator_last)
        ),
        "the robots confirm their tasks",
        30,
    )
    return ids


if __name__ == "__main__":
    # SIGTERM (e.g. from `timeout`) unwinds like Ctrl-C, so every process is stopped.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    sys.exit(main())
