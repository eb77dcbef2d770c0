"""A real ROSMC system for the executor tests and the executor benchmark.

:class:`RosmcSystem` starts the mission server, the robots' mission executors and,
optionally, the link emulator as real processes against a running ``rosmaster``;
:class:`Operator` is an in-process operator that calls the server's services
(retrying when a robot report moved the revision under it) and watches
``/rosmc/mission_events``; :class:`LinkEnd` lets a test play the ground or a robot
on one robot link; the ``journal_*`` functions read what the server journaled.

Used by ``tests/integration/test_executor.py`` (its ``rosmc`` fixture) and by
``bench/bench_executor.py``, which brings its own master. Not a test module: pytest
collects nothing here.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from io import BytesIO
from pathlib import Path
from typing import Any

import rosgraph
import rosmc.msg as wire
import rosmc.srv as srv
import rospy
from rosmc.msg import ErrorCode
from std_msgs.msg import Bool

from rosmc_server import interface
from rosmc_server.conversions import (
    mission_from_msg,
    param_to_msg,
    policy_in_force_from_msg,
    skill_to_msg,
)
from rosmc_server.core import MissionState, SkillInstance, SkillStatus
from rosmc_server.core.robots.commands import CommandKind
from rosmc_server.core.robots.radio import DatagramKind, parse_endpoint
from rosmc_server.core.robots.radio_auth import Sealer
from rosmc_server.core.robots.radio_key import RadioKey, obtain_key
from rosmc_server.recording import read_journal
from tests.conftest import wait_until

REPO_ROOT = Path(__file__).resolve().parents[2]
TEST_LIBRARY = REPO_ROOT / "tests" / "data" / "test_team.yaml"
S = SkillStatus
STOP_TIMEOUT = 30.0


def policy_words(msg: wire.LostLinkPolicy) -> str:
    """The policy in force a snapshot or agent state carries, in words ("" if unsaid)."""
    in_force = policy_in_force_from_msg(msg)
    return in_force.describe() if in_force is not None else ""


class OperatorError(RuntimeError):
    """The server refused an operator request."""

    def __init__(self, operation: str, code: int, message: str) -> None:
        super().__init__(f"{operation} refused (code {code}): {message}")
        self.code = code
        self.message = message


def init_test_node(name: str = "executor_tests") -> None:
    """Make this process a ROS node once (other tests may have done it already)."""
    if not rospy.core.is_initialized():
        rospy.init_node(name, anonymous=True, disable_signals=True)


def stop_action_server(server: Any) -> None:
    """Stop an ``actionlib.SimpleActionServer`` started by a test, its thread included.

    Its execute thread is not a daemon and runs until rospy shuts down, which a test
    process never asks for: left alone it would keep the interpreter from exiting.
    """
    server.action_server.stop()
    if server.execute_thread is None:
        return
    with server.terminate_mutex:
        server.need_to_terminate = True
    with server.execute_condition:
        server.execute_condition.notify_all()
    server.execute_thread.join(timeout=30.0)
    assert not server.execute_thread.is_alive(), "the action server's thread did not stop"


@dataclass
class EventLog:
    """``/rosmc/mission_events`` as received here, with the local receive time."""

    events: list[tuple[float, wire.MissionEvent]] = field(default_factory=list)
    lock: threading.Lock = field(default_factory=threading.Lock)

    def on_event(self, msg: wire.MissionEvent) -> None:
        """Subscriber callback."""
        with self.lock:
            self.events.append((time.time(), msg))

    def since(self, index: int) -> list[tuple[float, wire.MissionEvent]]:
        """Events from ``index`` on."""
        with self.lock:
            return list(self.events[index:])

    def __len__(self) -> int:
        with self.lock:
            return len(self.events)

    def statuses(self, skill_id: str) -> list[SkillStatus]:
        """Every status the events carried for ``skill_id``, in order, repeats collapsed."""
        went: list[SkillStatus] = []
        for _, event in self.since(0):
            for placed in event.put_skills:
                status = SkillStatus(placed.skill.status.value)
                if placed.skill.id == skill_id and went[-1:] != [status]:
                    went.append(status)
        return went

    def wait_went(self, skill_id: str, status: SkillStatus, timeout: float = 60.0) -> None:
        """Wait until an event showed ``skill_id`` at ``status``: a change that happened (and
        is kept), never a passing state a look at the mission could miss."""
        deadline = time.monotonic() + timeout
        while status not in self.statuses(skill_id):
            if time.monotonic() > deadline:
                raise AssertionError(
                    f"no event showed {skill_id} {status.name}: {self.statuses(skill_id)}"
                )
            time.sleep(0.02)


class Operator:
    """An operator talking to the mission server through its services."""

    def __init__(self, timeout: float = 20.0) -> None:
        init_test_node()
        self.timeout = timeout
        self._proxies: dict[str, rospy.ServiceProxy] = {}
        self.events = EventLog()
        self._subscriber = rospy.Subscriber(
            interface.EVENTS_TOPIC, wire.MissionEvent, self.events.on_event, queue_size=10000
        )
        self._blackouts: dict[str, rospy.Publisher] = {}

    def close(self) -> None:
        """Drop connections and the event subscription."""
        self._subscriber.unregister()
        for proxy in self._proxies.values():
            proxy.close()
        for publisher in self._blackouts.values():
            publisher.unregister()

    # -- raw services -----------------------------------------------------------
    def call(self, operation: str, **fields: Any) -> Any:
        """Call an operator service; raise OperatorError if it refuses."""
        proxy = self._proxies.get(operation)
        if proxy is None:
            name = interface.service_name(operation)
            rospy.wait_for_service(name, timeout=self.timeout)
            proxy = rospy.ServiceProxy(name, getattr(srv, interface.SERVICES[operation]))
            self._proxies[operation] = proxy
        response = proxy(**fields)
        code = getattr(response, "error_code", ErrorCode.NONE)
        if code != ErrorCode.NONE:
            raise OperatorError(operation, code, response.error)
        return response

    def change(self, operation: str, **fields: Any) -> Any:
        """A mutating call against the current revision, repeated while robots move it."""
        for _ in range(50):
            revision = self.call("get_mission").mission.revision
            try:
                return self.call(operation, base_revision=revision, **fields)
            except OperatorError as error:
                if error.code != ErrorCode.CONFLICT:
                    raise
        raise AssertionError(f"{operation}: the revision never stood still")

    # -- operations ---------------------------------------------------------------
    def mission(self) -> MissionState:
        """The server's mission now."""
        content, revision = mission_from_msg(self.call("get_mission").mission)
        return MissionState(content, revision)

    def add(
        self,
        agent: str,
        skill: str,
        params: Mapping[str, Any] | None = None,
        *,
        timeout: float = 0.0,
        max_retries: int = 0,
        label: str = "",
    ) -> str:
        """Add a skill to ``agent``'s blueprint; returns its id."""
        parameters = [param_to_msg(name, value) for name, value in (params or {}).items()]
        response = self.change(
            "add_skill",
            agent=agent,
            skill=skill,
            label=label,
            index=-1,
            parameters=parameters,
            timeout=timeout,
            max_retries=max_retries,
        )
        return str(response.skill_id)

    def edit(self, skill_id: str, params: Mapping[str, Any]) -> None:
        """Change parameter values of a blueprint skill."""
        parameters = [param_to_msg(name, value) for name, value in params.items()]
        self.change("edit_skill", skill_id=skill_id, parameters=parameters, label="")

    def sync(self, agent: str, upto: str = "") -> list[str]:
        """Upload ``agent``'s blueprint (up to ``upto``)."""
        return list(self.change("synchronize", agent=agent, upto_id=upto).skill_ids)

    def unsync(self, agent: str, from_id: str = "") -> list[str]:
        """Ask ``agent``'s robot to give back skills from ``from_id``."""
        return list(self.change("unsynchronize", agent=agent, from_id=from_id).skill_ids)

    def control(self, agent: str, command: int) -> None:
        """START, PAUSE, RESUME or STOP (``srv.ControlRequest``) one robot ("" = all)."""
        self.call("control", agent=agent, command=command)

    def start(self, agent: str = "") -> None:
        """Let the robot(s) execute."""
        self.control(agent, srv.ControlRequest.START)

    def retry_skill(self, skill_id: str) -> str:
        """Retry a failed skill; returns the fresh instance's id."""
        return str(self.change("retry_skill", skill_id=skill_id).new_skill_id)

    def skip_skill(self, skill_id: str) -> None:
        """Skip a failed skill."""
        self.change("skip_skill", skill_id=skill_id)

    def add_barrier(self, skill_ids: Sequence[str]) -> str:
        """Make skills start together; returns the barrier id."""
        return str(self.change("add_barrier", skill_ids=list(skill_ids)).barrier_id)

    def blackout(self, agent: str, on: bool) -> None:
        """Cut (or restore) ``agent``'s emulated link."""
        publisher = self._blackouts.get(agent)
        if publisher is None:
            publisher = rospy.Publisher(f"/{agent}/link/blackout", Bool, queue_size=10, latch=True)
            self._blackouts[agent] = publisher
            wait_until(lambda: publisher.get_num_connections() > 0, 30.0, "the link emulator")
        publisher.publish(Bool(data=on))

    def status_texts(self, skill_id: str) -> list[str]:
        """Every status text ``/rosmc/mission_events`` carried for ``skill_id``, in order."""
        return [
            placed.skill.status_text
            for _, event in self.events.since(0)
            for placed in event.put_skills
            if placed.skill.id == skill_id
        ]

    # -- waiting --------------------------------------------------------------------
    def wait_mission(
        self, predicate: Callable[[MissionState], bool], timeout: float, what: str
    ) -> MissionState:
        """Poll the mission until ``predicate`` holds; fail with the last state if not."""
        deadline = time.monotonic() + timeout
        state = self.mission()
        while not predicate(state):
            if time.monotonic() > deadline:
                raise AssertionError(f"timed out waiting for {what}:\n{describe(state)}")
            time.sleep(0.05)
            state = self.mission()
        return state

    def wait_status(
        self, skill_ids: Sequence[str], status: SkillStatus, timeout: float = 60.0
    ) -> MissionState:
        """Wait until every skill in ``skill_ids`` has ``status``."""
        names = ", ".join(skill_ids)
        return self.wait_mission(
            lambda m: all(m.skill(i).status is status for i in skill_ids),
            timeout,
            f"{names} to be {status.name}",
        )

    def agent_state(self, agent: str, timeout: float = 5.0) -> wire.AgentState:
        """``agent``'s entry of the next ``/rosmc/agent_states`` message."""
        box: list[wire.AgentStates] = []
        arrived = threading.Event()

        def on_states(msg: wire.AgentStates) -> None:
            box.append(msg)
            arrived.set()

        subscriber = rospy.Subscriber(interface.AGENT_STATES_TOPIC, wire.AgentStates, on_states)
        try:
            if not arrived.wait(timeout):
                raise AssertionError("no agent states published")
        finally:
            subscriber.unregister()
        return next(state for state in box[0].agents if state.agent == agent)

    def wait_links(self, agents: Sequence[str], timeout: float = 30.0) -> None:
        """Wait until the server has heard every agent's executor (link UP, numbering known)."""
        seen: dict[str, wire.AgentState] = {}
        done = threading.Event()

        def on_states(msg: wire.AgentStates) -> None:
            for state in msg.agents:
                seen[state.agent] = state
            if all(a in seen and seen[a].link.state == wire.LinkState.UP for a in agents):
                done.set()

        subscriber = rospy.Subscriber(interface.AGENT_STATES_TOPIC, wire.AgentStates, on_states)
        try:
            if not done.wait(timeout):
                raise AssertionError(f"links not up after {timeout} s: {seen}")
        finally:
            subscriber.unregister()


class LinkEnd:
    """One end of a robot link, played by the test: the ground or the robot.

    As ``"ground"`` it publishes commands and report acks and hears acks,
    reports and snapshots; as ``"robot"`` the other way round. Everything heard
    is kept in ``heard[topic field]``. With ``robot_names`` it uses the names of
    the robot's side of an emulated link: as ``"ground"``, it then hears what the
    robot says even while the emulator blacks the link out.
    """

    _GROUND_SENDS = (("command", wire.RobotCommand), ("report_ack", wire.ReportAck))
    _ROBOT_SENDS = (
        ("ack", wire.RobotAck),
        ("report", wire.RobotReport),
        ("snapshot", wire.ExecutorSnapshot),
    )

    def __init__(self, agent: str, side: str, robot_names: bool = False) -> None:
        init_test_node()
        topics = interface.robot_link(agent) if robot_names else interface.ground_link(agent)
        sends, hears = self._GROUND_SENDS, self._ROBOT_SENDS
        if side == "robot":
            sends, hears = hears, sends
        self.agent = agent
        self.heard: dict[str, list[Any]] = {name: [] for name, _ in hears}
        self._lock = threading.Lock()
        self._publishers = {
            name: rospy.Publisher(getattr(topics, name), kind, queue_size=100)
            for name, kind in sends
        }
        self._subscribers = [
            rospy.Subscriber(getattr(topics, name), kind, self._keep, callback_args=name)
            for name, kind in hears
        ]

    def _keep(self, msg: Any, name: str) -> None:
        with self._lock:
            self.heard[name].append(msg)

    def received(self, name: str) -> list[Any]:
        """Everything heard on ``name`` so far."""
        with self._lock:
            return list(self.heard[name])

    def connected(self, peers: int = 1) -> bool:
        """Whether every publisher and subscriber has ``peers`` connections."""
        return all(p.get_num_connections() >= peers for p in self._publishers.values()) and all(
            s.get_num_connections() >= peers for s in self._subscribers
        )

    def publish(self, name: str, msg: Any) -> None:
        """Send ``msg`` on topic ``name`` of the link."""
        self._publishers[name].publish(msg)

    def wait_heard(self, name: str, predicate: Callable[[Any], bool], timeout: float = 30.0) -> Any:
        """The first message on ``name`` that satisfies ``predicate`` (waits for it)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for msg in self.received(name):
                if predicate(msg):
                    return msg
            time.sleep(0.02)
        raise AssertionError(f"no matching {name} within {timeout} s: {self.received(name)[-3:]}")

    def close(self) -> None:
        """Unregister everything."""
        for publisher in self._publishers.values():
            publisher.unregister()
        for subscriber in self._subscribers:
            subscriber.unregister()


def command_msg(
    agent: str,
    seq: int,
    kind: CommandKind,
    skills: Sequence[SkillInstance] = (),
    skill_ids: Sequence[str] = (),
    barriers: Sequence[wire.Barrier] = (),
    argument: str = "",
) -> wire.RobotCommand:
    """A robot-link command as the ground would send it."""
    return wire.RobotCommand(
        agent=agent,
        seq=seq,
        type=int(kind),
        skills=[skill_to_msg(skill) for skill in skills],
        skill_ids=list(skill_ids),
        barriers=list(barriers),
        argument=argument,
    )


def team_key() -> RadioKey:
    """The radio key of the nodes this session starts (they share this process's ROS_HOME)."""
    return obtain_key(None, os.environ)[0]


def signal_datagram(msg: wire.BarrierSignal, sealer: Sealer | None = None) -> bytes:
    """A barrier signal as the radio side channel carries it, signed by ``sealer`` (default:
    a sender named as the signal's agent, holding the team's key)."""
    buffer = BytesIO()
    msg.serialize(buffer)
    sealer = sealer or Sealer(team_key(), msg.agent)
    return sealer.seal(DatagramKind.BARRIER_SIGNAL, buffer.getvalue())


def send_datagrams(name: str, *datagrams: bytes) -> None:
    """Send raw datagrams to ``name``'s radio endpoint, read from the directory."""
    key = f"{interface.RADIO_DIRECTORY}/{name}"
    endpoint = wait_until(lambda: rospy.get_param(key, ""), 30.0, f"{name}'s radio endpoint")
    host, port = parse_endpoint(endpoint)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
        for datagram in datagrams:
            udp.sendto(datagram, (host, port))


def describe(state: MissionState) -> str:
    """Every agent's task, one skill per line, for failure messages."""
    lines = [f"revision {state.revision}"]
    for agent in state.agents:
        for skill in state.task(agent):
            lines.append(
                f"  {agent} {skill.id} {skill.skill} {skill.status.name} "
                f"t={skill.transfer.name} r={skill.resolution.name} a={skill.attempt} "
                f"{skill.status_text!r}"
            )
    return "\n".join(lines)


# -- processes ------------------------------------------------------------------
def start_process(
    argv: Sequence[str], env: Mapping[str, str], log_path: Path
) -> subprocess.Popen[bytes]:
    """Start a node in its own session with its output in ``log_path``."""
    log_path.parent.mkdir(parents=True, exist_ok=True)
    with log_path.open("ab") as log:
        return subprocess.Popen(
            list(argv),
            env=dict(env),
            cwd=REPO_ROOT,
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )


def stop_process(process: subprocess.Popen[bytes], sig: int = signal.SIGINT) -> None:
    """Stop a process started by :func:`start_process` (SIGINT, then SIGKILL)."""
    if process.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, sig)
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(STOP_TIMEOUT)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(STOP_TIMEOUT)


@dataclass
class RosmcSystem:
    """Mission server, executors and link emulator as processes; stops them on close."""

    env: Mapping[str, str]
    workdir: Path
    library: Path = TEST_LIBRARY
    processes: dict[str, subprocess.Popen[bytes]] = field(default_factory=dict)

    @property
    def journal(self) -> Path:
        """The server's journal file."""
        return self.workdir / "journal.mcap"

    def state_file(self, agent: str) -> Path:
        """Where ``agent``'s executor keeps its state."""
        return self.workdir / "state" / f"{agent}.json"

    def log(self, name: str) -> Path:
        """The log file of process ``name``."""
        return self.workdir / "logs" / f"{name}.log"

    def _start(self, name: str, argv: Sequence[str], env: Mapping[str, str] | None = None) -> None:
        old = self.processes.get(name)
        if old is not None and old.poll() is None:
            raise RuntimeError(f"{name} is still running")
        self.processes[name] = start_process(argv, env or self.env, self.log(name))

    def start_server(self, *params: str) -> None:
        """Start the mission server with the test library and a journal in ``workdir``."""
        self._start(
            "server",
            [
                sys.executable,
                str(REPO_ROOT / "scripts" / "mission_server"),
                f"_library:={self.library}",
                f"_journal:={self.journal}",
                *params,
            ],
        )

    def start_executor(self, agent: str, robot_side: bool | None = False, *params: str) -> None:
        """Start ``agent``'s executor (behind the emulator if ``robot_side``; None: not given)."""
        env = dict(self.env, ROS_NAMESPACE=f"/{agent}")
        side = [] if robot_side is None else [f"_robot_side:={str(robot_side).lower()}"]
        self._start(
            agent,
            [
                sys.executable,
                str(REPO_ROOT / "scripts" / "mission_executor"),
                f"_agent:={agent}",
                f"_state_file:={self.state_file(agent)}",
                f"_library:={self.library}",  # the robots' skills must fit the server's library
                *side,
                *params,
            ],
            env,
        )

    def start_emulator(self, agents: Sequence[str], *params: str) -> None:
        """Start the link emulator for ``agents``."""
        self._start(
            "emulator",
            [
                sys.executable,
                str(REPO_ROOT / "scripts" / "link_emulator"),
                f"_agents:=[{','.join(agents)}]",
                *params,
            ],
        )

    def stop(self, name: str, sig: int = signal.SIGINT) -> int | None:
        """Stop one process (``signal.SIGKILL`` for a crash); returns its exit code."""
        process = self.processes[name]
        stop_process(process, sig)
        return process.returncode

    def alive(self, name: str) -> bool:
        """Whether process ``name`` is running."""
        process = self.processes.get(name)
        return process is not None and process.poll() is None

    def close(self) -> None:
        """Stop everything, the server last (so it journals the robots' last reports)."""
        others = [p for name, p in self.processes.items() if name != "server"]
        for process in others:  # all at once: each rospy node takes a while to go
            if process.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(process.pid, signal.SIGINT)
        for process in others:
            stop_process(process)
        if "server" in self.processes:
            stop_process(self.processes["server"])
        self._forget_private_params()

    def _forget_private_params(self) -> None:
        """Delete the private parameters this system's nodes were started with.

        They outlive the nodes on the session's master, and a later node of the same name
        started without one (another module's server, with the default library) would
        read this system's value.
        """
        master = rosgraph.Master("/rosmc_tests", master_uri=self.env["ROS_MASTER_URI"])
        for name in self.processes:
            node = {"server": "/rosmc/mission_server", "emulator": "/rosmc/link_emulator"}.get(
                name, f"/{name}/mission_executor"
            )
            with contextlib.suppress(rosgraph.MasterError, OSError):
                if master.hasParam(node):
                    master.deleteParam(node)

    def log_tails(self, lines: int = 30, names: Sequence[str] = ()) -> str:
        """The end of the log of every process (or of those in ``names``)."""
        out = []
        for name in names or list(self.processes):
            try:
                text = self.log(name).read_text(errors="replace").splitlines()
            except OSError:
                text = ["<no log>"]
            out.append(f"--- {name} ---\n" + "\n".join(text[-lines:]))
        return "\n".join(out)


# -- the journal -------------------------------------------------------------------
@dataclass(frozen=True)
class Transition:
    """One status a skill took, as the journal recorded it."""

    revision: int
    status: SkillStatus
    transfer: int
    attempt: int
    text: str


def journal_timelines(path: Path) -> dict[str, list[Transition]]:
    """Every skill's sequence of (status, transfer) changes from a closed journal."""
    result = read_journal(path, [interface.EVENTS_TOPIC])
    timelines: dict[str, list[Transition]] = {}
    for record in result.records:
        event = record.message
        for placed in event.put_skills:
            skill = placed.skill
            entry = Transition(
                event.revision,
                SkillStatus(skill.status.value),
                skill.transfer,
                skill.attempt,
                skill.status_text,
            )
            line = timelines.setdefault(skill.id, [])
            if not line or (line[-1].status, line[-1].transfer) != (entry.status, entry.transfer):
                line.append(entry)
    return timelines


def journal_reports(path: Path) -> list[wire.RobotReport]:
    """The robot reports the server journaled, in journal order."""
    return [r.message for r in read_journal(path, [interface.ROBOT_REPORTS_TOPIC]).records]


def assert_released_together(path: Path, members: Sequence[str]) -> None:
    """No barrier member started before the last one arrived (robot clocks, one machine).

    The release skew in milliseconds is a figure for ``bench/bench_executor.py``; a test
    checks the order: every member's RUNNING ``started`` follows every member's last
    SYNCWAITING report.
    """
    arrived: dict[str, float] = {}
    for report in journal_reports(path):
        if report.status.value == S.SYNCWAITING:
            arrived[report.skill_id] = report.stamp.to_sec()
    started = running_stamps(path)
    assert set(members) <= set(arrived), f"a member never waited: {members}, {arrived}"
    last = max(arrived[m] for m in members)
    early = {m: started[m] for m in members if started[m] < last}
    assert not early, f"started before the last member arrived at {last}: {early}"


def running_stamps(path: Path) -> dict[str, float]:
    """Each skill's ``started`` stamp from its first RUNNING report (robot clock)."""
    stamps: dict[str, float] = {}
    for report in journal_reports(path):
        if report.status.value == S.RUNNING and report.skill_id not in stamps:
            stamps[report.skill_id] = report.started
    return stamps
