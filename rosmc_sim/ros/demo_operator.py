"""The scripted operator of the demo mission: ``/rosmc/demo_operator``.

It plays the operators of the paper's sample-return mission through the
public operator services only (like the ``rosmc`` CLI would):

1. plan: the drone surveys an area; the manipulator rover fetches the Wi-Fi box
   for a spot; the science rover heads out; synchronize and start;
2. adapt: the planned Wi-Fi spot at the foot of the ridge lies in its radio shadow,
   so the not-yet-run ``place_box`` is unsynchronized, its marker moved, and
   re-synchronized (a spot on the ridge itself the server would refuse at once);
3. once the drone has discovered a region, both rovers identify its stones
   together (a skill barrier), the manipulator picks the best stone and brings
   it to the lander;
4. print a live progress line per robot, then a summary.

Subscribes ``/rosmc/sim/science`` (rosmc/ScienceState) and ``/rosmc/agent_states``;
calls the ``/rosmc/*`` operator services. Parameters: ``~timeout`` (wall s, 600),
``~result_file`` (path: where the exit status is written at the end; "" = nowhere),
``~cwd`` (a relative ``~result_file`` is taken from there; launch files set it).
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence
from typing import TypeVar

import rosmc.msg as wire
import rospy

from rosmc_server.common.ros.graph_join import join_graph
from rosmc_server.common.ros.station import launch_path
from rosmc_server.core import MarkerType, Pose, RosmcError, SkillStatus, TaskMarker
from rosmc_server.core.model.changes import EventKind
from rosmc_server.core.robots.link import LinkStatus
from rosmc_server.core.views.vocabulary import OPERATOR_EVENTS, counted
from rosmc_server.ros.client import ControlCommand, MissionClient, MissionWatch

from .topics import SCIENCE_TOPIC

T = TypeVar("T")

SURVEY = ((9.0, 3.0), (23.0, 3.0), (23.0, 15.0), (9.0, 15.0))
WIFI_SPOT_PLANNED = Pose(19.0, -8.0)  # at the foot of the ridge, in its radio shadow
WIFI_SPOT_ADAPTED = Pose(15.0, -13.0, 0.0, 0.0, 0.0, -0.6)


class DemoOperator:
    """Runs the scripted mission and reports on it."""

    def __init__(self, client: MissionClient, deadline: float) -> None:
        self.client = client
        self.deadline = deadline
        self.watch = MissionWatch(events=True, states=True)
        self.science: wire.ScienceState | None = None
        self._science_lock = threading.Lock()
        self._science_sub = rospy.Subscriber(SCIENCE_TOPIC, wire.ScienceState, self._on_science)
        self.events: Counter[EventKind] = Counter()
        self.started_wall = time.monotonic()
        self.started_sim = rospy.get_time()
        self._next_progress = 0.0

    def _on_science(self, msg: wire.ScienceState) -> None:
        with self._science_lock:
            self.science = msg

    # -- the mission ----------------------------------------------------------------
    def run(self) -> int:
        """Plan, start, adapt and finish the mission; 0 if it completed."""
        self._wait("every robot link is up", self._links_up)
        client = self.client
        client.get_mission()
        say("planning: survey, Wi-Fi box, science rover on its way")
        client.add_task_marker(
            TaskMarker("Survey area", MarkerType.AREA, Pose(), tuple(Pose(x, y) for x, y in SURVEY))
        )
        client.add_task_marker(TaskMarker("Wi-Fi spot", MarkerType.POSE, WIFI_SPOT_PLANNED))
        client.add_skill("drone", "take_off", {"altitude": 8.0})
        client.add_skill(
            "drone", "fly_over", {"altitude": 8.0, "spacing": 4.0}, bindings={"area": "Survey area"}
        )
        client.add_skill("drone", "return_to_lander")
        client.add_skill("drone", "recharge", {"level": 1.0})
        client.add_skill("manipulator_rover", "pick_box", {"box": "wifi_box"})
        place = client.add_skill(
            "manipulator_rover", "place_box", bindings={"target": "Wi-Fi spot"}
        ).skill_id
        client.add_skill("science_rover", "navigate_to", {"target": {"x": 8.0, "y": 2.0}})
        for agent in ("drone", "manipulator_rover", "science_rover"):
            client.synchronize(agent)
        self._wait("the robots stored their skills", self._nothing_uploading)
        client.control(ControlCommand.START)
        say("started; the planned Wi-Fi spot lies in the ridge's radio shadow: adapting")
        client.unsynchronize("manipulator_rover", place)
        self._wait("the manipulator rover gave place_box back", lambda: self._editable(place))
        client.move_task_marker("Wi-Fi spot", WIFI_SPOT_ADAPTED)
        client.synchronize("manipulator_rover")
        region = self._wait("the drone discovered a region", self._discovered_region)
        if region is None:
            return 1
        say(f"{region.name} discovered at ({region.x:.1f}, {region.y:.1f}): planning the sampling")
        self._plan_sampling(region)
        done = self._wait("every synchronized skill finished", self._all_settled, fail_fast=True)
        return 0 if done else 1

    def _plan_sampling(self, region: wire.SampleRegion) -> None:
        client = self.client
        at = Pose(region.x, region.y)
        client.add_task_marker(TaskMarker(region.name, MarkerType.POSITION, at))
        near = region.radius + 1.0
        sci_spot = {"x": region.x - near, "y": region.y - 1.0}
        man_spot = {"x": region.x + near * 0.3, "y": region.y - near}
        client.add_skill("science_rover", "navigate_to", {"target": sci_spot})
        sci = client.add_skill(
            "science_rover", "identify_stones", bindings={"position": region.name}
        )
        client.add_skill("science_rover", "return_to_lander")
        client.add_skill("manipulator_rover", "navigate_to", {"target": man_spot})
        man = client.add_skill(
            "manipulator_rover", "identify_stones", bindings={"position": region.name}
        )
        client.add_skill("manipulator_rover", "pick_stone", bindings={"position": region.name})
        client.add_skill("manipulator_rover", "deposit_at_lander")
        client.add_barrier([sci.skill_id, man.skill_id])
        for agent in ("science_rover", "manipulator_rover"):
            client.synchronize(agent)
        client.control(ControlCommand.START)

    # -- conditions -------------------------------------------------------------------
    def _links_up(self) -> bool:
        states = self.watch.take_agent_states() or {}
        return bool(states) and all(s.link is LinkStatus.UP for s in states.values())

    def _nothing_uploading(self) -> bool:
        return not any(s.transfer for s in self.client.get_mission().skills())

    def _editable(self, skill_id: str) -> bool:
        return self.client.get_mission().skill(skill_id).is_editable

    def _discovered_region(self) -> wire.SampleRegion | None:
        with self._science_lock:
            regions = list(self.science.regions) if self.science else []
        return regions[0] if regions else None

    def _all_settled(self) -> bool:
        skills = [s for s in self.client.get_mission().skills() if s.status is not SkillStatus.IDLE]
        failed = [s for s in skills if s.status is SkillStatus.FAILURE and not s.is_settled]
        if failed:
            raise RuntimeError(f"'{failed[0].id}' failed: {failed[0].status_text}")
        return bool(skills) and all(s.is_settled for s in skills)

    def _wait(self, what: str, condition: Callable[[], T], fail_fast: bool = False) -> T | None:
        """Poll ``condition`` until it holds; its result, or None if a check stopped it."""
        say(f"waiting until {what}")
        while time.monotonic() < self.deadline and not rospy.is_shutdown():
            self._drain_events()
            self._progress()
            try:
                result = condition()
            except RuntimeError as error:
                say(f"stopped: {error}")
                return None
            if result:
                return result
            time.sleep(0.2)
        raise TimeoutError(f"gave up waiting until {what}")

    # -- reporting -------------------------------------------------------------------
    def _drain_events(self) -> None:
        while (event := self.watch.next_event(timeout=0)) is not None:
            self.events[event.kind] += 1

    def _progress(self) -> None:
        now = time.monotonic()
        if now < self._next_progress:
            return
        self._next_progress = now + 2.0
        states = self.watch.take_agent_states() or {}
        mission = self.client.get_mission()
        for agent in mission.agents:
            state = states.get(agent)
            current = next((s for s in mission.task(agent) if s.status.is_active), None)
            doing = (
                f"{current.skill} {current.status.name} {current.status_text}"
                if current
                else "idle"
            )
            battery = (
                f"{state.battery * 100:3.0f}%" if state and state.battery is not None else "  ?"
            )
            link = state.link if state else "?"
            print(
                f"  [{rospy.get_time() - self.started_sim:6.1f} s] {agent:18} bat {battery} "
                f"link {link:7} {doing}",
                flush=True,
            )

    def summary(self) -> str:
        """The closing summary: score, times, skills per robot, operator changes."""
        self._drain_events()
        mission = self.client.get_mission()
        with self._science_lock:
            science = self.science
        lines = ["", "=== Demo mission summary ==="]
        if science is not None:
            lines.append(
                f"score: {science.score:.2f} from {counted(science.stones_delivered, 'stone')}"
            )
            lines += [f"  {line}" for line in science.events]
        lines.append(
            f"sim time: {rospy.get_time() - self.started_sim:.1f} s, "
            f"wall time: {time.monotonic() - self.started_wall:.1f} s"
        )
        for agent in mission.agents:
            done = [s.skill for s in mission.task(agent) if s.status is SkillStatus.SUCCESS]
            lines.append(f"{agent}: {counted(len(done), 'skill')} executed: {', '.join(done)}")
        changes = sum(n for kind, n in self.events.items() if kind in OPERATOR_EVENTS)
        lines.append(f"operator changes: {changes}; mission revision {mission.revision}")
        return "\n".join(lines)


def say(text: str) -> None:
    """One operator line."""
    print(f"operator: {text}", flush=True)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``demo_operator``."""
    args = rospy.myargv(list(argv) if argv is not None else sys.argv)
    argparse.ArgumentParser(
        prog="demo_operator", description="Scripted operator of the ROSMC demo mission."
    ).parse_args(args[1:])
    join_graph("demo_operator")
    deadline = time.monotonic() + float(rospy.get_param("~timeout", 600.0))
    client = MissionClient(timeout=30.0)
    operator = DemoOperator(client, deadline)
    try:
        code = operator.run()
    except (RosmcError, TimeoutError) as error:
        say(f"the demo failed: {error}")
        code = 1
    print(operator.summary(), flush=True)
    result_file = str(rospy.get_param("~result_file", ""))
    if result_file:
        launch_path(result_file).write_text(f"{code}\n")
    return code
