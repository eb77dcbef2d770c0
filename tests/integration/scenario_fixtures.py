"""A simulated ROSMC team as real processes, and an operator that drives it through services.

:class:`Team` starts what ``launch/sim.launch`` and ``launch/mission_server.launch`` start
(the mission server with the Mars library, the sim node ``/rosmc/sim`` publishing
``/clock``, the link emulator, one mission executor per robot behind it), with
``/use_sim_time`` set, against the session's ``rosmaster``. The tests set a few private
parameters the launch files leave at their defaults (the sim step, the server's link
timeout, the executors' snapshot period) so that minutes of sim time take seconds.

:class:`Operator` is the only way the tests change anything: :class:`MissionClient` (the
public operator services), :class:`MissionWatch` (``/rosmc/agent_states``), the mission
events (``/rosmc/mission_events``, kept: what a skill went through), and the sim's public
topics ``/rosmc/sim/science`` and ``/<robot>/telemetry``.
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import subprocess
import sys
import threading
import time
import xmlrpc.client
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import rosgraph
import rosmc.msg as wire
import rospy
from rosgraph_msgs.msg import Clock

from rosmc_server.core import AgentStatus, MissionState, RosmcError, SkillStatus, Transfer
from rosmc_server.interface import EVENTS_TOPIC
from rosmc_server.ros.client import ControlCommand, MissionClient, MissionWatch
from rosmc_sim.ros.topics import SCIENCE_TOPIC, blackout_topic
from tests.conftest import wait_until
from tests.integration.executor_fixtures import EventLog

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "tests" / "data" / "scenario_team.yaml"
LIBRARY = REPO / "rosmc_server" / "config" / "mars_team.yaml"
ROBOTS = ("drone", "science_rover", "manipulator_rover")
USE_SIM_TIME = "/use_sim_time"
EMULATOR_NODE = "/rosmc/link_emulator"
CLOCK_TOPIC = "/clock"
STOP_TIMEOUT = 30.0
POLL = 0.05  # wall seconds between looks at something that changes on its own
S = SkillStatus
HELD = (S.IDLE_SYNCHRONIZED, S.SYNCWAITING, S.RUNNING, S.PAUSED)  # on a robot, not finished
T = TypeVar("T")


@dataclass(frozen=True)
class TeamSettings:
    """How the team runs (sim seconds unless said otherwise).

    Attributes:
        real_time_factor: Sim seconds per wall second (0: as fast as possible).
        step: Sim seconds per simulation step (fewer ``/clock`` messages at high factors).
        link_timeout: Wall seconds of silence before the server calls a link DOWN.
        snapshot_period: Wall seconds between the executors' snapshots (their heartbeat).
        latency: One-way latency of the emulated links.
        library: The skill library of the server and of the executors.
    """

    scenario: Path = SCENARIO
    library: Path = LIBRARY
    real_time_factor: float = 100.0
    step: float = 0.1
    link_timeout: float = 1.0
    snapshot_period: float = 0.25
    latency: float = 0.0


@dataclass
class Team:
    """The server, the sim node, the link emulator and the executors, as processes."""

    env: Mapping[str, str]
    workdir: Path
    settings: TeamSettings = field(default_factory=TeamSettings)
    processes: dict[str, subprocess.Popen[bytes]] = field(default_factory=dict)

    @property
    def journal_dir(self) -> Path:
        """Where the server writes its MCAP journal."""
        return self.workdir / "journal"

    def log(self, name: str) -> Path:
        """The log file of process ``name``."""
        return self.workdir / f"{name}.log"

    def start(self) -> None:
        """Start every process (the caller waits until the links are up)."""
        forget_params()
        rospy.set_param(USE_SIM_TIME, True)  # as sim.launch does; read by each node at start
        self.journal_dir.mkdir(parents=True, exist_ok=True)
        self._start(
            "server",
            "mission_server",
            library=self.settings.library,
            journal_dir=self.journal_dir,
            link_timeout=self.settings.link_timeout,
            agent_state_rate=10.0,
        )
        self._start(
            "sim",
            "sim_node",
            scenario=self.settings.scenario,
            real_time_factor=self.settings.real_time_factor,
            step=self.settings.step,
        )
        self.start_emulator(self.settings.latency)
        for robot in ROBOTS:
            self._start(
                robot,
                "mission_executor",
                {"ROS_NAMESPACE": f"/{robot}"},
                agent=robot,
                skills=f"rosmc_sim.ros.robot_skills:{robot}_skills",
                library=self.settings.library,
                robot_side=True,
                state_file="",
                snapshot_period=self.settings.snapshot_period,
            )

    def start_emulator(self, latency: float) -> None:
        """(Re)start the link emulator with a one-way ``latency`` (messages in it are lost).

        Call :meth:`wait_emulator` before relying on coverage.
        """
        if "emulator" in self.processes:
            stop_process(self.processes.pop("emulator"))
        self._start("emulator", "link_emulator", agents=f"[{','.join(ROBOTS)}]", latency=latency)

    def wait_emulator(self, timeout: float = 30.0) -> None:
        """Wait until the link emulator hears the sim's coverage of every robot.

        The emulator relays from its start, so links can be up before it subscribed to the
        blackouts; a robot leaving coverage in that gap would keep its link (and a gap of a
        wall second is 100 sim seconds at a factor of 100).
        """
        for robot in ROBOTS:
            topic = blackout_topic(robot)
            wait_until(
                functools.partial(subscribed, EMULATOR_NODE, topic),
                timeout,
                f"the link emulator hears {topic}",
            )

    def _start(
        self, name: str, script: str, env: Mapping[str, str] | None = None, **params: object
    ) -> None:
        argv = [sys.executable, str(REPO / "scripts" / script)]
        argv += [f"_{key}:={_param_text(value)}" for key, value in params.items()]
        with self.log(name).open("ab") as log:
            self.processes[name] = subprocess.Popen(
                argv,
                env={**self.env, **(env or {})},
                cwd=REPO,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def dead(self) -> list[str]:
        """The processes that exited."""
        return [name for name, process in self.processes.items() if process.poll() is not None]

    def close(self) -> None:
        """Stop everything (all at once: each rospy node takes a moment), the server last."""
        others = [p for name, p in self.processes.items() if name != "server"]
        for process in others:
            _signal(process, signal.SIGINT)
        for process in others:
            stop_process(process)
        if "server" in self.processes:
            stop_process(self.processes["server"])
        forget_params()
        with contextlib.suppress(KeyError):
            rospy.delete_param(USE_SIM_TIME)

    def dump_stacks(self) -> None:
        """Have every live process print its threads' stacks into its log (SIGUSR1)."""
        for process in self.processes.values():
            if process.poll() is None:
                _signal(process, signal.SIGUSR1)
        time.sleep(1.0)  # the dumps are written by the processes themselves

    def log_tails(self, lines: int = 25) -> str:
        """The end of every process's log, for failure messages."""
        out = []
        for name in self.processes:
            try:
                text = self.log(name).read_text(errors="replace").splitlines()
            except OSError:
                text = ["<no log>"]
            out.append(f"--- {name} ---\n" + "\n".join(text[-lines:]))
        return "\n".join(out)


def forget_params() -> None:
    """Delete the private parameters of the team's nodes (``_key:=value`` outlives a node)."""
    for namespace in (
        "/rosmc/mission_server",
        "/rosmc/sim",
        "/rosmc/link_emulator",
        *(f"/{robot}/mission_executor" for robot in ROBOTS),
    ):
        with contextlib.suppress(KeyError):
            rospy.delete_param(namespace)


def subscribed(node: str, topic: str) -> bool:
    """Whether ``node`` has a live inbound connection on ``topic`` (its ``getBusInfo``)."""
    try:
        uri = rosgraph.Master(rospy.get_name()).lookupNode(node)
        answer: Any = xmlrpc.client.ServerProxy(uri).getBusInfo(rospy.get_name())
    except (rosgraph.MasterException, OSError, xmlrpc.client.Error):
        return False
    code, _, connections = answer
    # (id, publisher, direction, transport, topic, connected, info) per connection
    return bool(code == 1 and any(c[2] == "i" and c[4] == topic and c[5] for c in connections))


def _param_text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _signal(process: subprocess.Popen[bytes], sig: int) -> None:
    if process.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, sig)


def stop_process(process: subprocess.Popen[bytes]) -> None:
    """SIGINT the process group, then SIGKILL whatever is left."""
    _signal(process, signal.SIGINT)
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(STOP_TIMEOUT)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(STOP_TIMEOUT)


# -- what the operator sees ---------------------------------------------------------------------
class Latest:
    """The latest message of a topic."""

    def __init__(self, topic: str, msg_type: type) -> None:
        self._lock = threading.Lock()
        self._last: Any = None
        self._subscriber = rospy.Subscriber(topic, msg_type, self._on_msg, queue_size=10)

    def _on_msg(self, msg: Any) -> None:
        with self._lock:
            self._last = msg

    @property
    def last(self) -> Any:
        """The latest message, None before the first."""
        with self._lock:
            return self._last

    def close(self) -> None:
        """Unsubscribe."""
        self._subscriber.unregister()


class Science:
    """``/rosmc/sim/science``: the latest state, and every event line since subscribing."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._last: wire.ScienceState | None = None
        self.lines: list[str] = []
        self._subscriber = rospy.Subscriber(
            SCIENCE_TOPIC, wire.ScienceState, self._on_msg, queue_size=100
        )

    def _on_msg(self, msg: wire.ScienceState) -> None:
        with self._lock:
            self._last = msg
            self.lines.extend(msg.events)

    @property
    def last(self) -> wire.ScienceState | None:
        """The latest science state."""
        with self._lock:
            return self._last

    def score(self) -> float:
        """The team's score so far (it only grows)."""
        state = self.last
        return state.score if state is not None else 0.0

    def region(self, name: str) -> wire.SampleRegion | None:
        """A discovered region, None while it is hidden."""
        state = self.last
        regions = state.regions if state is not None else []
        return next((r for r in regions if r.name == name), None)

    def identified_by(self, name: str) -> str | None:
        """Who identified a discovered region's stones ("", "science_rover", "collaborative")."""
        region = self.region(name)
        return None if region is None else str(region.identified_by)

    def close(self) -> None:
        """Unsubscribe."""
        self._subscriber.unregister()


@dataclass(frozen=True)
class Timed:
    """A service call and how long it took (wall seconds)."""

    operation: str
    seconds: float


class Operator:
    """The operator: services through :class:`MissionClient`, eyes on the public topics."""

    def __init__(self) -> None:
        self.client = MissionClient(timeout=30.0)
        self.watch = MissionWatch(events=False, states=True)
        self.science = Science()
        self.telemetry = {robot: Latest(f"/{robot}/telemetry", wire.Telemetry) for robot in ROBOTS}
        self.timings: list[Timed] = []
        self.events = EventLog()
        self._events = rospy.Subscriber(
            EVENTS_TOPIC, wire.MissionEvent, self.events.on_event, queue_size=10000
        )

    def close(self) -> None:
        """Unsubscribe and drop connections."""
        self._events.unregister()
        self.watch.close()
        self.science.close()
        for latest in self.telemetry.values():
            latest.close()
        self.client.close()

    def timed(self, operation: str, call: Callable[[], T]) -> T:
        """Run ``call`` (one service call) and remember its wall time."""
        start = time.monotonic()
        try:
            return call()
        finally:
            self.timings.append(Timed(operation, time.monotonic() - start))

    # -- the mission ---------------------------------------------------------------------
    def mission(self) -> MissionState:
        """The mission now."""
        return self.client.get_mission()

    def wait_mission(
        self, predicate: Callable[[MissionState], bool], timeout: float, what: str
    ) -> MissionState:
        """Poll the mission until ``predicate`` holds; fail with every task if it does not."""
        deadline = time.monotonic() + timeout
        while True:
            state = self.client.fetch_mission()
            if predicate(state):
                return state
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out waiting until {what}:\n{describe(state)}")
            time.sleep(POLL)

    def wait_status(
        self, skill_ids: Iterable[str], status: SkillStatus, timeout: float
    ) -> MissionState:
        """Wait until every one of ``skill_ids`` has ``status``; fail early on a FAILURE."""
        ids = list(skill_ids)

        def reached(state: MissionState) -> bool:
            failed = [i for i in ids if state.skill(i).status is S.FAILURE]
            if failed and status is not S.FAILURE:
                skill = state.skill(failed[0])
                raise AssertionError(f"{skill.skill} {skill.id} failed: {skill.status_text}")
            return all(state.skill(i).status is status for i in ids)

        return self.wait_mission(reached, timeout, f"{', '.join(ids)} are {status.name}")

    def wait_stored(self, agent: str, timeout: float = 20.0) -> MissionState:
        """Wait until ``agent``'s robot confirmed every upload and removal."""
        return self.wait_mission(
            lambda m: all(s.transfer is Transfer.NONE for s in m.task(agent)),
            timeout,
            f"{agent}'s robot answered every transfer",
        )

    def sync_and_start(self, agents: Sequence[str], timeout: float = 20.0) -> None:
        """Synchronize each agent's whole blueprint, wait for the robots, and start them."""
        for agent in agents:
            self.client.synchronize(agent)
        for agent in agents:
            self.wait_stored(agent, timeout)
            self.client.control(ControlCommand.START, agent)

    def new_mission(self) -> None:
        """Start an empty mission; after a failed test, stop and take back what robots hold."""
        try:
            self.client.new_mission(keep_markers=False)
            return
        except RosmcError:
            pass
        for robot in ROBOTS:
            with contextlib.suppress(RosmcError):
                self.client.control(ControlCommand.STOP, robot)
        self.wait_mission(
            lambda m: not any(s.status.is_active for s in m.skills()), 30.0, "the robots stop"
        )
        for robot in ROBOTS:
            with contextlib.suppress(RosmcError):
                self.client.unsynchronize(robot)
        self.wait_mission(
            lambda m: (
                not any(s.status in HELD or s.transfer is not Transfer.NONE for s in m.skills())
            ),
            30.0,
            "the robots gave their skills back",
        )
        self.client.new_mission(keep_markers=False)

    # -- the robots ------------------------------------------------------------------------
    def agent_state(self, agent: str) -> AgentStatus | None:
        """What the server last said about ``agent``'s robot."""
        states = self.watch.wait_agent_states(timeout=30.0) or {}
        return states.get(agent)

    def wait_link(self, agent: str, link: str, timeout: float) -> AgentStatus:
        """Wait until the server calls ``agent``'s link ``link`` (``"up"`` or ``"down"``)."""

        def reached() -> AgentStatus | None:
            state = self.agent_state(agent)
            return state if state is not None and state.link == link else None

        return wait_until(reached, timeout, f"the server calls {agent}'s link {link}")

    def wait_links_up(self, timeout: float = 60.0) -> None:
        """Wait until the server hears every robot."""
        for robot in ROBOTS:
            self.wait_link(robot, "up", timeout)

    def where(self, robot: str) -> wire.Telemetry:
        """The robot's latest telemetry (pose, battery, coverage), straight from the sim."""
        return wait_until(lambda: self.telemetry[robot].last, 30.0, f"{robot}'s telemetry")

    def sim_now(self) -> float:
        """A sim time at least as late as the call (one ``/clock`` message heard afresh).

        Telemetry comes twice a wall second, which is 50 sim seconds at a factor of 100;
        this process keeps wall time, so it asks the clock when it needs the sim's.
        """
        heard: list[float] = []
        arrived = threading.Event()

        def on_clock(msg: Clock) -> None:
            if not heard:
                heard.append(msg.clock.to_sec())
                arrived.set()

        subscriber = rospy.Subscriber(CLOCK_TOPIC, Clock, on_clock, queue_size=1)
        try:
            if not arrived.wait(10.0):
                raise AssertionError("no /clock within 10 s")
        finally:
            subscriber.unregister()
        return heard[0]

    def wait_robot(
        self,
        robot: str,
        predicate: Callable[[wire.Telemetry], bool],
        what: str,
        timeout: float = 30.0,
    ) -> wire.Telemetry:
        """Wait until a telemetry message of the robot satisfies ``predicate``; that message.

        Every message is tested as it arrives (not only the latest at each look), so a
        robot that passes where the predicate holds is seen there however busy the test is.
        """
        seen: list[wire.Telemetry] = []
        last = self.telemetry[robot].last
        if last is not None and predicate(last):
            return last

        def keep(telemetry: wire.Telemetry) -> None:
            if not seen and predicate(telemetry):
                seen.append(telemetry)

        subscriber = rospy.Subscriber(f"/{robot}/telemetry", wire.Telemetry, keep, queue_size=100)
        try:
            return wait_until(lambda: seen[0] if seen else None, timeout, f"{robot}: {what}")
        finally:
            subscriber.unregister()


def describe(state: MissionState) -> str:
    """Every agent's task, one skill per line, for failure messages."""
    lines = [f"revision {state.revision}"]
    for agent in state.agents:
        for skill in state.task(agent):
            lines.append(
                f"  {agent} {skill.id} {skill.skill} {skill.status.name} "
                f"t={skill.transfer.name} a={skill.attempt} {skill.status_text!r}"
            )
    return "\n".join(lines)
