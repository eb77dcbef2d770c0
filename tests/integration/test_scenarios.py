"""The paper's pilot study end to end: real master, server, sim node, link emulator, executors.

``test_the_demo_mission_*`` runs ``scripts/rosmc_demo`` (``make demo``) as a user would, on
its own master. Every other test shares one simulated team (:mod:`scenario_fixtures`,
``tests/data/scenario_team.yaml``) at a real-time factor of :data:`RTF`, starts from an empty
mission, and changes the mission only through the operator services (``MissionClient``);
it looks at the robots only through the sim's public topics (``/rosmc/sim/science``,
``/<robot>/telemetry``) and the server's agent states. Each test ends with every skill
settled, so the next can start a new mission; where a robot is when a test starts does not
matter (each plans from where it is, with absolute targets).
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rospy

from rosmc_server.core import (
    LostLinkPolicy,
    MarkerType,
    Pose,
    SkillStatus,
    TaskMarker,
    Transfer,
)
from rosmc_server.core.model.changes import EventKind
from rosmc_server.core.views.vocabulary import OPERATOR_EVENTS
from rosmc_server.interface import AGENT_STATES_TOPIC, EVENTS_TOPIC, MISSION_TOPIC
from rosmc_server.recording import read_journal
from rosmc_server.ros.client import ControlCommand
from rosmc_sim.ros.demo_operator import WIFI_SPOT_ADAPTED
from tests.conftest import wait_until
from tests.integration.failures import body_failed
from tests.integration.scenario_fixtures import Operator, Team, TeamSettings

pytestmark = pytest.mark.integration

REPO = Path(__file__).resolve().parents[2]
RTF = 100.0  # sim seconds per wall second for the shared team
DEMO_RTF = 30.0
S = SkillStatus
SCIENCE, ARM, DRONE = "science_rover", "manipulator_rover", "drone"
FAST = 1.0  # m/s: the rovers' top speed in the test scenario (the library's default is 0.5)


def square(x: float, y: float, half: float) -> tuple[Pose, ...]:
    """The corners of a square around (x, y)."""
    return tuple(
        Pose(x + dx * half, y + dy * half) for dx, dy in ((-1, -1), (1, -1), (1, 1), (-1, 1))
    )


def area(name: str, corners: tuple[Pose, ...]) -> TaskMarker:
    """An AREA task marker."""
    cx = sum(c.x for c in corners) / len(corners)
    cy = sum(c.y for c in corners) / len(corners)
    return TaskMarker(name, MarkerType.AREA, Pose(cx, cy), corners)


def target(x: float, y: float, speed: float = FAST) -> dict[str, Any]:
    """navigate_to parameters."""
    return {"target": {"x": x, "y": y}, "speed": speed}


# -- 1. the demo, as `make demo` runs it ------------------------------------------------------
def test_the_demo_mission_completes_with_a_score_and_a_full_recording(tmp_path: Path) -> None:
    result = subprocess.run(
        [
            sys.executable,
            str(REPO / "scripts" / "rosmc_demo"),
            "--real-time-factor",
            str(DEMO_RTF),
            "--journal-dir",
            str(tmp_path),
            "--timeout",
            "150",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    out = result.stdout
    assert result.returncode == 0, out[-6000:] + result.stderr[-3000:]
    # a normal end prints no error (roslaunch once reported the operator's end as a death)
    noise = [
        line
        for line in (out + result.stderr).splitlines()
        if "has died" in line or re.search(r"\bERROR\b|\[ERROR\]|Traceback", line)
    ]
    assert not noise, noise
    assert "rosmc_demo: completed" in out
    score = re.search(r"^score: ([0-9.]+) from (\d+) stone", out, re.M)
    changes = re.search(r"^operator changes: (\d+); mission revision (\d+)", out, re.M)
    recording = re.search(r"^rosmc_demo: mission recording: (\S+\.mcap)$", out, re.M)
    assert score and changes and recording, out[-4000:]
    assert float(score.group(1)) > 0.0 and int(score.group(2)) >= 1

    journal = read_journal(recording.group(1))
    assert journal.clean, journal.warnings
    events = journal.messages(EVENTS_TOPIC)
    assert journal.messages(MISSION_TOPIC)[0].revision == 1, "a fresh mission starts at 1"
    assert [e.revision for e in events] == list(range(2, len(events) + 2)), "revision gap"
    assert events[-1].revision == int(changes.group(2))
    kinds = Counter(EventKind(e.kind) for e in events)
    made = {kind: n for kind, n in kinds.items() if kind in OPERATOR_EVENTS}
    assert sum(made.values()) == int(changes.group(1)), made
    expected = {
        EventKind.MARKER_ADDED,
        EventKind.SKILL_ADDED,
        EventKind.SYNC_REQUESTED,
        EventKind.UNSYNC_REQUESTED,
        EventKind.MARKER_MOVED,
        EventKind.BARRIER_ADDED,
    }
    assert expected <= made.keys(), made
    assert kinds[EventKind.SYNC_CONFIRMED] == kinds[EventKind.SYNC_REQUESTED]
    _check_adaptation(events)
    _check_robots_recorded(journal, float(score.group(1)))
    _check_info(Path(recording.group(1)), float(score.group(1)), events[-1].revision)


def _check_info(path: Path, score: float, revision: int) -> None:
    """``rosmc info`` summarizes the recording from the file alone."""
    result = subprocess.run(
        [sys.executable, str(REPO / "scripts" / "rosmc"), "--json", "info", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    info = json.loads(result.stdout)
    assert info["revisions"] == [1, revision]  # a fresh mission starts at 1
    assert info["final_score"] == pytest.approx(score, abs=0.01)
    outcomes = {robot["agent"]: robot for robot in info["robots"]}
    assert set(outcomes) == {DRONE, SCIENCE, ARM}
    assert all(r["succeeded"] >= 2 and r["failed"] == 0 for r in outcomes.values()), outcomes
    assert info["records"]["/tf"] > 0 and info["changes"]["SYNC_REQUESTED"] >= 3


def _check_robots_recorded(journal: Any, score: float) -> None:
    """The recording shows the robots moving, their states, the site and the score."""
    frames = {t.child_frame_id for m in journal.messages("/tf") for t in m.transforms}
    assert frames == {f"{robot}/base_link" for robot in (DRONE, SCIENCE, ARM)}
    drone_heights = [
        t.transform.translation.z
        for m in journal.messages("/tf")
        for t in m.transforms
        if t.child_frame_id == "drone/base_link"
    ]
    assert max(drone_heights) > 2.0, "the drone was recorded flying"
    states = journal.messages(AGENT_STATES_TOPIC)
    assert len(states) >= 10
    assert {s.executor_state for m in states for s in m.agents} >= {"running"}
    assert journal.messages("/rosmc/sim/world"), "the site"
    assert journal.messages("/rosmc/sim/science")[-1].score == pytest.approx(score, abs=0.01)


def _check_adaptation(events: list[Any]) -> None:
    """place_box was unsynchronized, its marker moved, then re-synchronized, and it ran there."""
    unsync = next(e for e in events if e.kind == EventKind.UNSYNC_REQUESTED)
    place = unsync.put_skills[0].skill
    assert place.skill == "place_box"

    def later(kind: EventKind, after: int) -> Any:
        return next(
            e
            for e in events
            if e.kind == kind
            and e.revision > after
            and any(p.skill.id == place.id for p in e.put_skills)
        )

    confirmed = later(EventKind.UNSYNC_CONFIRMED, unsync.revision)
    moved = later(EventKind.MARKER_MOVED, confirmed.revision)
    resynced = later(EventKind.SYNC_REQUESTED, moved.revision)
    assert moved.put_markers[0].name == "Wi-Fi spot"
    pose = moved.put_markers[0].pose
    assert (pose.x, pose.y) == pytest.approx((WIFI_SPOT_ADAPTED.x, WIFI_SPOT_ADAPTED.y))
    followed = next(p.skill for p in moved.put_skills if p.skill.id == place.id)
    assert any(param.name == "target" for param in followed.parameters)
    ran = later(EventKind.STATUS_CHANGED, resynced.revision)
    assert ran.revision > resynced.revision
    last = [p.skill for e in events for p in e.put_skills if p.skill.id == place.id][-1]
    assert last.status.value == S.SUCCESS and "deployed" in last.status_text


# -- the shared team ------------------------------------------------------------------------
@pytest.fixture(scope="module")
def team(ros_master: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Team]:
    """The simulated team, its links up."""
    if not rospy.core.is_initialized():  # before /use_sim_time is set: this process keeps wall time
        rospy.init_node("scenario_tests", anonymous=True, disable_signals=True)
    running = Team(
        dict(ros_master.env),
        tmp_path_factory.mktemp("team"),
        TeamSettings(real_time_factor=RTF),
    )
    try:
        running.start()
        yield running
    finally:
        running.close()
        print(running.log_tails())


@pytest.fixture(scope="module")
def module_operator(team: Team) -> Iterator[Operator]:
    """One operator for the module (its subscriptions stay connected)."""
    operator = Operator()
    try:
        operator.wait_links_up(timeout=60.0)
        team.wait_emulator()
        yield operator
    finally:
        operator.close()


@pytest.fixture
def op(module_operator: Operator, team: Team, request: pytest.FixtureRequest) -> Iterator[Operator]:
    """The operator, on an empty mission; every process must outlive the test.

    After a failed test every process prints its threads' stacks, and the logs' ends are
    shown with the failure (a robot that stopped answering says where it stands).
    """
    module_operator.new_mission()
    module_operator.timings.clear()
    yield module_operator
    if body_failed(request):
        team.dump_stacks()
        print(team.log_tails(lines=200))
    assert not team.dead(), f"{team.dead()} died:\n{team.log_tails()}"


# -- 2. collaboration --------------------------------------------------------------------------
def test_collaborative_identification_scores_the_region_maximum(op: Operator) -> None:
    c = op.client
    start_score = op.science.score()
    assert op.science.region("RSS North") is None, "regions stay hidden until explored"
    # About 12 s of the drone's 30 s of flight.
    c.add_task_marker(area("north survey", square(0.0, 9.0, 2.0)))
    survey = [
        c.add_skill(DRONE, "recharge", {"level": 1.0}).skill_id,
        c.add_skill(DRONE, "take_off", {"altitude": 2.0}).skill_id,
        c.add_skill(
            DRONE, "fly_over", {"altitude": 2.0, "spacing": 4.0}, bindings={"area": "north survey"}
        ).skill_id,
        c.add_skill(DRONE, "return_to_lander").skill_id,
    ]
    # The rovers head out while the drone looks, then wait there, idle and in coverage, for
    # the sampling skills, under their library default (return_to_link once idle 60 s
    # without the ground, wall seconds whatever the sim's speed).
    staging = [
        c.add_skill(SCIENCE, "navigate_to", target(-2.0, 6.5)).skill_id,
        c.add_skill(ARM, "navigate_to", target(2.0, 6.5)).skill_id,
    ]
    op.sync_and_start([DRONE, SCIENCE, ARM])

    region = wait_until(lambda: op.science.region("RSS North"), 30.0, "the drone finds RSS North")
    assert region.identified_by == "" and region.stones_left == 1
    c.add_task_marker(TaskMarker("RSS North", MarkerType.POSITION, Pose(region.x, region.y)))
    at_rss = {"position": "RSS North"}
    sci = c.add_skill(SCIENCE, "identify_stones", bindings=at_rss).skill_id
    arm = c.add_skill(ARM, "identify_stones", bindings=at_rss).skill_id
    c.add_barrier([sci, arm])
    sampling = [
        sci,
        arm,
        c.add_skill(ARM, "pick_stone", bindings=at_rss).skill_id,
        c.add_skill(ARM, "deposit_at_lander").skill_id,
        c.add_skill(SCIENCE, "return_to_lander").skill_id,
    ]
    op.sync_and_start([SCIENCE, ARM])
    op.wait_status(survey + staging + sampling, S.SUCCESS, timeout=60.0)

    assert op.science.identified_by("RSS North") == "collaborative"
    wait_until(lambda: op.science.score() > start_score, 30.0, "the score counts the stone")
    assert op.science.score() - start_score == pytest.approx(region.max_score)
    assert any("RSS North together" in line for line in op.science.lines)


def test_without_identification_a_stone_scores_the_minimum(op: Operator) -> None:
    c = op.client
    start_score = op.science.score()
    c.add_task_marker(area("west", square(-8.0, 0.0, 2.5)))
    explore = c.add_skill(SCIENCE, "explore", bindings={"area": "west"}).skill_id
    op.sync_and_start([SCIENCE])

    region = wait_until(lambda: op.science.region("RSS West"), 60.0, "the rover finds RSS West")
    c.add_task_marker(TaskMarker("RSS West", MarkerType.POSITION, Pose(region.x, region.y)))
    fetch = [
        c.add_skill(ARM, "pick_stone", bindings={"position": "RSS West"}).skill_id,
        c.add_skill(ARM, "deposit_at_lander").skill_id,
    ]
    op.sync_and_start([ARM])
    op.wait_status([explore, *fetch], S.SUCCESS, timeout=60.0)

    assert op.science.identified_by("RSS West") == ""
    wait_until(lambda: op.science.score() > start_score, 30.0, "the score counts the stone")
    assert op.science.score() - start_score == pytest.approx(0.1)
    assert any("RSS West stone 1 worth 0.10" in line for line in op.science.lines)


# -- stop, then start ---------------------------------------------------------------------------
def test_a_stopped_skill_runs_again_on_start(op: Operator) -> None:
    """As `rosmc stop --help` promises: stop sends the skill back, start runs it again."""
    c = op.client
    # The slowest drive the library allows: at a factor of 100 a faster one could end between
    # two looks at the mission on a loaded machine, before the stop.
    drive = c.add_skill(SCIENCE, "navigate_to", target(-6.0, -6.0, speed=0.05)).skill_id
    back = c.add_skill(SCIENCE, "return_to_lander").skill_id
    op.sync_and_start([SCIENCE])
    op.events.wait_went(drive, S.RUNNING)  # its event: a look at the mission could miss it
    c.control(ControlCommand.STOP, SCIENCE)
    op.wait_status([drive], S.IDLE_SYNCHRONIZED, timeout=60.0)  # stopped: it stays so
    c.control(ControlCommand.START, SCIENCE)
    op.wait_status([drive, back], S.SUCCESS, timeout=90.0)
    op.events.wait_went(drive, S.SUCCESS)  # the mission may show it before the event
    went = op.events.statuses(drive)
    assert went[-4:] == [S.RUNNING, S.IDLE_SYNCHRONIZED, S.RUNNING, S.SUCCESS], went
    skill = op.mission().skill(drive)
    assert skill.attempt == 1 and "cancel" not in skill.status_text


# -- 3. coverage ---------------------------------------------------------------------------------
FAR = (20.0, 0.0)  # beyond the lander's 12 m of Wi-Fi
WIFI_SPOT = (11.0, 0.0)  # the box lands a metre ahead: (12, 0), 8 m from FAR


def near(telemetry: Any, point: tuple[float, float], within: float = 0.3) -> bool:
    """Whether a telemetry pose lies within ``within`` metres of ``point``."""
    return math.dist((telemetry.pose.x, telemetry.pose.y), point) <= within


def test_out_of_coverage_the_robot_goes_on_and_a_wifi_box_brings_it_back(op: Operator) -> None:
    c = op.client
    # With its library default it would drive back to its link once idle a minute
    # (test_lost_link_scenario.py); here it waits where its task ends.
    c.set_lost_link_policy(SCIENCE, LostLinkPolicy())
    # The last leg is slow: at a factor of 100 the emulator may apply a blackout a tenth of a
    # wall second late (its blackout and relay callbacks are separate threads), so the skill
    # the server must not hear of ends well after the robot left coverage.
    out = [
        c.add_skill(SCIENCE, "navigate_to", target(16.0, 0.0)).skill_id,
        c.add_skill(SCIENCE, "navigate_to", target(*FAR, speed=0.1)).skill_id,
    ]
    op.sync_and_start([SCIENCE])

    # Out of coverage: the server loses the link after its link timeout; a synchronize waits
    # for contact; the robot still executes what it holds.
    op.wait_link(SCIENCE, "down", timeout=30.0)
    op.wait_robot(SCIENCE, lambda t: near(t, FAR) and not t.in_coverage, "it reaches the far spot")
    home = c.add_skill(SCIENCE, "navigate_to", target(6.0, -2.0)).skill_id
    assert c.synchronize(SCIENCE).note.startswith(f"queued for {SCIENCE}: out of contact")
    state = op.mission()
    assert state.skill(home).transfer is Transfer.UPLOADING, "it waits for contact"
    assert state.skill(out[1]).status is not S.SUCCESS, "the server cannot know yet"

    # The manipulator deploys the Wi-Fi box between the lander and the far spot.
    c.add_task_marker(TaskMarker("wifi spot", MarkerType.POSE, Pose(*WIFI_SPOT)))
    deploy = [
        c.add_skill(ARM, "pick_box", {"box": "wifi_box"}).skill_id,
        c.add_skill(ARM, "place_box", bindings={"target": "wifi spot"}).skill_id,
    ]
    op.sync_and_start([ARM])
    op.wait_status(deploy, S.SUCCESS, timeout=60.0)

    # The far spot is covered now: the link comes back there, the server learns that both
    # skills finished while it could not hear the robot, and the synchronize that waited
    # reaches the rover, which drives home at once (it was never stopped).
    state = op.wait_status([*out, home], S.SUCCESS, timeout=60.0)
    placed = state.skill(deploy[1]).finished
    assert state.skill(out[1]).finished < placed, "it finished out of coverage"
    assert state.skill(home).started > placed, "home left only once the rover could be heard"


# -- 4. battery ----------------------------------------------------------------------------------
PAD = {"area": "pad"}


def landed(telemetry: Any, after: float) -> bool:
    """Whether the telemetry is newer than ``after`` (sim time) and shows the drone down."""
    return bool(telemetry.stamp.to_sec() > after and telemetry.pose.z < 0.01)


def test_a_drone_that_flies_too_long_runs_empty_and_recharges_at_the_lander(op: Operator) -> None:
    c = op.client
    # Passes over the lander (the area lies within its charging radius): a quick one with
    # lanes 1.5 m apart takes 9 s of the 30 s battery, a thorough one 0.5 m apart 21 s.
    c.add_task_marker(area("pad", square(0.0, 0.0, 3.0)))
    flight = [
        c.add_skill(DRONE, "recharge", {"level": 1.0}).skill_id,
        c.add_skill(DRONE, "take_off", {"altitude": 2.0}).skill_id,
        c.add_skill(DRONE, "fly_over", {"altitude": 2.0, "spacing": 1.5}, bindings=PAD).skill_id,
        c.add_skill(DRONE, "fly_over", {"altitude": 2.0, "spacing": 0.5}, bindings=PAD).skill_id,
    ]
    op.sync_and_start([DRONE])
    state = op.wait_status([flight[-1]], S.FAILURE, timeout=60.0)
    assert [state.skill(i).status for i in flight[:-1]] == [S.SUCCESS] * 3
    assert state.skill(flight[-1]).status_text == "battery empty"
    # An empty drone cannot hover: it comes down where it is, here next to the lander.
    failed_at = state.skill(flight[-1]).finished
    down = op.wait_robot(DRONE, lambda t: landed(t, after=failed_at), "the empty drone is down")
    assert down.battery == 0.0 and math.hypot(down.pose.x, down.pose.y) < 4.5

    # A retry fails at once (the battery is still empty); skip it, recharge, fly home.
    again = c.retry_skill(flight[-1]).new_skill_id
    state = op.wait_status([again], S.FAILURE, timeout=30.0)
    assert state.skill(again).status_text == "battery empty"
    c.skip_skill(again)
    home = [
        c.add_skill(DRONE, "recharge", {"level": 1.0}).skill_id,
        c.add_skill(DRONE, "take_off", {"altitude": 2.0}).skill_id,
        c.add_skill(DRONE, "return_to_lander").skill_id,
    ]
    op.sync_and_start([DRONE])
    state = op.wait_status(home, S.SUCCESS, timeout=60.0)
    assert state.skill(home[0]).status_text == "battery at 100 %"
    done_at = state.skill(home[-1]).finished
    pad = op.wait_robot(DRONE, lambda t: landed(t, after=done_at), "the drone landed")
    assert math.hypot(pad.pose.x, pad.pose.y) < 0.1 and pad.battery > 0.5


# -- 5. twenty minutes of latency ----------------------------------------------------------------
LATENCY = 1200.0  # sim seconds, one way: 12 wall seconds at a factor of 100
SLOW = 0.05  # m/s (the library's least): 10 m legs take 200 s, running on under the latency
LEGS = ((8.0, -6.0), (8.0, 4.0), (-2.0, 4.0))  # all inside the lander's coverage


def test_with_20_minutes_of_latency_edits_answer_at_once_and_the_robot_goes_on(
    op: Operator, team: Team
) -> None:
    c = op.client
    legs = [c.add_skill(SCIENCE, "navigate_to", target(*LEGS[0])).skill_id]
    legs += [c.add_skill(SCIENCE, "navigate_to", target(*p, speed=SLOW)).skill_id for p in LEGS[1:]]
    # Twenty minutes of silence is an outage to the rover's default policy (a minute idle):
    # this mission wants it to go on. Stored on the robot before the latency sets in, as the
    # legs are; only the start travels under the latency, so the legs cannot run before it
    # (restarting the link emulator takes seconds of a loaded machine, hundreds of sim s).
    # An earlier test left the rover started, and a started robot runs what it is sent: stop
    # it first (it has nothing to do, so it only stops).
    c.control(ControlCommand.STOP, SCIENCE)
    c.set_lost_link_policy(SCIENCE, LostLinkPolicy())
    wait_until(
        lambda: (
            (s := op.agent_state(SCIENCE))
            and s.executor_state == "stopped"
            and s.policy == "on link loss: continue"
        ),
        30.0,
        "the rover stopped, with the continue policy",
    )
    c.synchronize(SCIENCE)
    op.wait_stored(SCIENCE)
    try:
        team.start_emulator(LATENCY)
        team.wait_emulator()
        latency_from = op.sim_now()
        # Twenty minutes away, the robot is silent: its link is DOWN, and yet every edit of
        # the blueprint answers at once; a synchronize waits for contact, and can be taken
        # back before it ever leaves.
        op.wait_link(SCIENCE, "down", timeout=60.0)
        c.control(ControlCommand.START, SCIENCE)  # waits for contact, then 20 minutes more
        edits_from = op.sim_now()
        _edit_under_latency(op)
        # Answered before a message could even reach the robot: none waited on it.
        assert op.sim_now() - edits_from < LATENCY, "an edit waited on the robot"
        assert c.synchronize(SCIENCE).note.startswith(f"queued for {SCIENCE}: out of contact")
        c.unsynchronize(SCIENCE)
        assert op.mission().skill(legs[-1]).transfer is Transfer.NONE
        # The robot goes on with what it holds; the server hears of it 20 minutes later.
        end = LEGS[-1]
        op.wait_robot(SCIENCE, lambda t: near(t, end), f"the rover reaches {end}", timeout=240.0)
        assert op.mission().skill(legs[-1]).status is not S.SUCCESS
        state = op.wait_status(legs, S.SUCCESS, timeout=120.0)
        heard_by = op.sim_now()
        started, finished = state.skill(legs[0]).started, state.skill(legs[-1]).finished
        assert latency_from < started, "the legs ran under the latency"
        assert heard_by - finished >= LATENCY, (finished, heard_by)  # heard a latency later
    finally:
        team.start_emulator(0.0)
        team.wait_emulator()
        op.wait_link(SCIENCE, "up", timeout=30.0)
    print(
        "edits under latency:",
        ", ".join(f"{t.operation} {t.seconds * 1e3:.1f} ms" for t in op.timings),
    )
    assert len(op.timings) == 11, op.timings


def _edit_under_latency(op: Operator) -> None:
    """Plan the manipulator's next steps and rework the rover's blueprint; each call timed."""
    c = op.client
    t = op.timed
    rock = {"position": "rock"}
    rock_at = TaskMarker("rock", MarkerType.POSITION, Pose(5, 5))
    t("add_task_marker", lambda: c.add_task_marker(rock_at))
    a = t("add_skill", lambda: c.add_skill(ARM, "navigate_to", target(4.0, 4.0))).skill_id
    b = t("add_skill", lambda: c.add_skill(ARM, "pick_stone", bindings=rock))
    d = t("add_skill", lambda: c.add_skill(SCIENCE, "identify_stones", bindings=rock))
    e = t("add_skill", lambda: c.add_skill(SCIENCE, "return_to_lander")).skill_id
    t("edit_skill", lambda: c.edit_skill(a, {"target": {"x": 4.5, "y": 3.5}}))
    t("move_task_marker", lambda: c.move_task_marker("rock", Pose(5.5, 5.0)))
    t("add_barrier", lambda: c.add_barrier([b.skill_id, d.skill_id]))
    t("reorder_skills", lambda: c.reorder_skills(SCIENCE, [e, d.skill_id]))
    t("delete_skills", lambda: c.delete_skills([e]))
    t("get_mission", c.get_mission)
    state = c.get_mission()
    assert [s.skill for s in state.task(ARM) if s.is_editable] == ["navigate_to", "pick_stone"]
    assert state.skill(a).params["target"] == Pose(4.5, 3.5)
