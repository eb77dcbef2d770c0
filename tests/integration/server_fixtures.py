"""Fixtures for the mission-server integration tests: a real server, real rospy clients.

A test module loads them with ``pytest_plugins = ["tests.integration.server_fixtures"]``.
Everything runs against the session's ``ros_master`` (tests/conftest.py): the server is
``scripts/mission_server`` in its own process, the tests talk to it through persistent
``rospy.ServiceProxy`` objects and plain subscribers, as any operator GUI would.

``client_node`` (session)
    This process as a rospy node (once; other tests may have made it one already).
``start_server`` (function)
    ``start_server(name, **params)`` starts a server with private parameters
    ``_key:=value`` (``journal_dir`` defaults to a fresh temporary directory) and waits
    until it serves; every server is stopped when the test ends.
``module_server`` / ``client`` / ``fresh`` (module, module, function)
    One server shared by a module, a client of it, and a reset to an empty mission.
"""

from __future__ import annotations

import contextlib
import copy
import io
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import genpy
import pytest
import rosmc.msg as wire
import rosmc.srv as srv
import rospy

from rosmc_server import interface
from rosmc_server.common.ros.connections import publishers_count_me

REPO = Path(__file__).resolve().parents[2]
SERVER_SCRIPT = REPO / "scripts" / "mission_server"
READY_LINE = "mission server ready"
START_TIMEOUT = 60.0
STOP_TIMEOUT = 30.0
# Servers of this process that are running: only one can own the mission server's names.
_RUNNING: list[ServerProcess] = []
MUTATING = tuple(
    op for op in interface.SERVICES if op not in ("get_mission", "get_library", "save_mission")
)


# -- the server process ----------------------------------------------------------------
class ServerProcess:
    """One ``mission_server`` process with its log file."""

    def __init__(self, env: dict[str, str], log_path: Path, params: dict[str, object]) -> None:
        self.env = env
        self.log_path = log_path
        self.params = params
        args = [f"_{key}:={_param_text(value)}" for key, value in params.items()]
        self.argv = [sys.executable, str(SERVER_SCRIPT), *args]
        self.process: subprocess.Popen[bytes] | None = None
        self.stopped = False  # stopped on purpose (not died)

    @property
    def pid(self) -> int:
        """The server's process id."""
        assert self.process is not None
        return self.process.pid

    def start(self, timeout: float = START_TIMEOUT) -> ServerProcess:
        """Start the server and wait until its services are advertised.

        Any other server this process started is stopped first: a second node of the
        same name would shut the first one down anyway.
        """
        for other in list(_RUNNING):
            other.stop()
        forget_server_params()
        self.stopped = False
        _RUNNING.append(self)
        with self.log_path.open("ab") as log:
            log.write(f"--- start {' '.join(self.argv[1:])}\n".encode())
            log.flush()
            offset = log.tell()
            self.process = subprocess.Popen(
                self.argv,
                env=self.env,
                cwd=REPO,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise AssertionError(f"mission server exited at start:\n{self.log()[-4000:]}")
            if READY_LINE in self.log_since(offset):
                return self
            time.sleep(0.02)
        raise AssertionError(f"mission server not ready in {timeout} s:\n{self.log()[-4000:]}")

    @property
    def alive(self) -> bool:
        """Whether the process is still running."""
        return self.process is not None and self.process.poll() is None

    def log(self) -> str:
        """Everything the server printed (over all its starts)."""
        return self.log_path.read_text(errors="replace")

    def log_since(self, offset: int) -> str:
        """What the server printed after byte ``offset`` of its log."""
        with self.log_path.open("rb") as log:
            log.seek(offset)
            return log.read().decode(errors="replace")

    def kill9(self) -> None:
        """SIGKILL the server: no shutdown hook runs, the journal is left as a crash leaves it."""
        if self in _RUNNING:
            _RUNNING.remove(self)
        if self.process is not None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait(STOP_TIMEOUT)

    def stop(self) -> int | None:
        """SIGINT (a clean shutdown), then SIGKILL if it does not end; the exit code."""
        if self in _RUNNING:
            _RUNNING.remove(self)
        self.stopped = True
        if self.process is None:
            return None
        if self.process.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.process.pid, signal.SIGINT)
            try:
                self.process.wait(STOP_TIMEOUT)
            except subprocess.TimeoutExpired:
                self.kill9()
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.process.pid, signal.SIGKILL)
        return self.process.returncode

    def peak_rss_kib(self) -> int:
        """The server's peak resident set size (VmHWM), in KiB."""
        for line in Path(f"/proc/{self.pid}/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
        raise AssertionError("no VmHWM in /proc status")


def forget_server_params() -> None:
    """Delete the server's private parameters from the master.

    ``_key:=value`` arguments stay on the parameter server after the node ends, so a
    server started later without ``_resume:=true`` would still resume (and with the old
    journal). Every start here gets exactly the parameters it was given.
    """
    with contextlib.suppress(KeyError):
        rospy.delete_param(interface.SERVER_NODE)


def _param_text(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


StartServer = Callable[..., ServerProcess]


def _launcher(env: dict[str, str], base: Path) -> tuple[StartServer, list[ServerProcess]]:
    started: list[ServerProcess] = []

    def start(name: str = "server", **params: object) -> ServerProcess:
        if "journal" not in params:
            journal_dir = base / f"{name}-{len(started)}-journal"
            journal_dir.mkdir(parents=True, exist_ok=True)
            params.setdefault("journal_dir", journal_dir)
        # Mission files may live in any of this session's temporary directories.
        params.setdefault("mission_dir", base.parent)
        server = ServerProcess(env, base / f"{name}-{len(started)}.log", params)
        started.append(server)
        return server.start()

    return start, started


def _stop_all(started: list[ServerProcess]) -> None:
    for server in reversed(started):
        code = server.stop()
        tail = "\n".join(server.log().splitlines()[-25:])
        print(f"--- {server.log_path.name} (exit {code}) ---\n{tail}")
    forget_server_params()  # leave no parameters behind for other tests' servers


@pytest.fixture(scope="session")
def client_node(ros_master: Any) -> Any:
    """This test process as a rospy node on the session's master."""
    if not rospy.core.is_initialized():
        rospy.init_node("rosmc_server_tests", anonymous=True, disable_signals=True)
    return ros_master


@pytest.fixture
def start_server(client_node: Any, tmp_path: Path) -> Iterator[StartServer]:
    """``start_server(name="server", **params)``: a running server, stopped after the test."""
    start, started = _launcher(dict(client_node.env), tmp_path)
    yield start
    _stop_all(started)


@pytest.fixture(scope="module")
def module_server(
    client_node: Any, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[ServerProcess]:
    """One server for a whole test module (agent states at 10 Hz to keep tests short)."""
    start, started = _launcher(dict(client_node.env), tmp_path_factory.mktemp("server"))
    server = start("module", agent_state_rate=10.0)
    yield server
    assert server.alive or server.stopped, "the module's mission server died"
    _stop_all(started)


@pytest.fixture(scope="module")
def client(module_server: ServerProcess) -> Iterator[Client]:
    """A client with persistent connections to the module's server."""
    with Client() as mission_client:
        yield mission_client


@pytest.fixture
def fresh(client: Client, module_server: ServerProcess) -> Iterator[Client]:
    """The module's client, with the mission reset to empty (no skills, no markers).

    A test that started a server of its own stopped the module's: it starts again here.
    """
    if not module_server.alive:
        client.close()
        module_server.start()
    response = client.call("new_mission", base_revision=client.revision(), keep_markers=False)
    assert response.error_code == 0, response.error
    yield client
    assert module_server.alive or module_server.stopped, "the mission server died in the test"


# -- clients -------------------------------------------------------------------------
class Client:
    """Persistent service proxies to every operator service of the server."""

    def __init__(self, timeout: float = 10.0) -> None:
        self._timeout = timeout
        self._proxies: dict[str, rospy.ServiceProxy] = {}

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def proxy(self, operation: str) -> rospy.ServiceProxy:
        """The (persistent) proxy of one operation, made on first use."""
        if operation not in self._proxies:
            name = interface.service_name(operation)
            rospy.wait_for_service(name, timeout=self._timeout)
            service_class = getattr(srv, interface.SERVICES[operation])
            self._proxies[operation] = rospy.ServiceProxy(name, service_class, persistent=True)
        return self._proxies[operation]

    def request(self, operation: str, **fields: Any) -> Any:
        """A request message of ``operation`` with ``fields`` set."""
        service_class = getattr(srv, interface.SERVICES[operation])
        return service_class._request_class(**fields)

    def call(self, operation: str, **fields: Any) -> Any:
        """Call ``operation``; a ``rospy.ServiceException`` fails the test (handler raised)."""
        return self.send(operation, self.request(operation, **fields))

    def send(self, operation: str, request: Any) -> Any:
        """Call ``operation`` with a ready-made request message."""
        proxy = self.proxy(operation)
        try:
            return proxy.call(request)
        except rospy.ServiceException:
            self._drop(operation)
            raise

    def _drop(self, operation: str) -> None:
        proxy = self._proxies.pop(operation, None)
        if proxy is not None:
            with contextlib.suppress(Exception):
                proxy.close()

    def mission(self) -> wire.Mission:
        """The current mission (GetMission)."""
        return self.call("get_mission").mission

    def revision(self) -> int:
        """The current revision."""
        return int(self.mission().revision)

    def close(self) -> None:
        """Close every persistent connection (needed after a server restart)."""
        for operation in list(self._proxies):
            self._drop(operation)


def serialized(msg: genpy.Message) -> bytes:
    """The ROS 1 wire bytes of a message."""
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()


def mission_key(mission: wire.Mission) -> bytes:
    """A mission's wire bytes without its stamp: equal keys, equal missions."""
    unstamped = copy.deepcopy(mission)
    unstamped.stamp = genpy.Time()
    return serialized(unstamped)


def skill_ids(mission: wire.Mission, agent: str | None = None) -> list[str]:
    """Every skill id of the mission (of one agent), in task order."""
    return [
        skill.id
        for task in mission.tasks
        if agent is None or task.agent == agent
        for skill in task.skills
    ]


def task_of(mission: wire.Mission, agent: str) -> list[wire.Skill]:
    """The skills of ``agent``'s task."""
    for task in mission.tasks:
        if task.agent == agent:
            return list(task.skills)
    raise AssertionError(f"no task for {agent}")


def assert_one_sentence(text: str) -> None:
    """An operator error: one non-empty line of text, no traceback."""
    assert text.strip(), "the error is empty"
    assert "\n" not in text and "\r" not in text, f"the error is not one line: {text!r}"
    assert "Traceback" not in text, text


def assert_rejected(client: Client, operation: str, code: int | None = None, **fields: Any) -> Any:
    """Call ``operation``; it must fail with an error (``code`` if given) and change nothing."""
    before = client.mission()
    response = client.call(operation, **fields)
    after = client.mission()
    assert response.error_code != wire.ErrorCode.NONE, f"{operation} {fields} was accepted"
    if code is not None:
        assert response.error_code == code, (response.error_code, response.error)
    assert_one_sentence(response.error)
    assert mission_key(after) == mission_key(before), f"{operation} {fields} changed the mission"
    if hasattr(response, "revision"):
        assert response.revision == before.revision
    return response


def accepted(response: Any) -> Any:
    """Check a response is a success and return it."""
    assert response.error_code == wire.ErrorCode.NONE, (response.error_code, response.error)
    assert response.error == ""
    return response


# -- subscribers ---------------------------------------------------------------------------
class Recorder:
    """Collects the messages of one topic, with their receive times."""

    def __init__(self, topic: str, msg_type: type, connect_timeout: float = 10.0) -> None:
        self.messages: list[Any] = []
        self.times: list[float] = []
        self._cond = threading.Condition()
        self._subscriber = rospy.Subscriber(topic, msg_type, self._on_message, queue_size=10000)
        deadline = time.monotonic() + connect_timeout
        while self._subscriber.get_num_connections() == 0:
            assert time.monotonic() < deadline, f"no publisher of {topic} connected"
            time.sleep(0.01)
        # The subscriber counts the connection before the publisher does: a message
        # published in between would not reach this recorder.
        while not publishers_count_me(self._subscriber):
            assert time.monotonic() < deadline, f"the publisher of {topic} never counted us"
            time.sleep(0.01)

    def _on_message(self, msg: Any) -> None:
        with self._cond:
            self.messages.append(msg)
            self.times.append(time.monotonic())
            self._cond.notify_all()

    def wait_for(self, predicate: Callable[[list[Any]], bool], timeout: float = 30.0) -> list[Any]:
        """Wait until ``predicate(messages)`` holds; return a copy of the messages."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while not predicate(self.messages):
                left = deadline - time.monotonic()
                assert left > 0, f"timed out; got {len(self.messages)} messages"
                self._cond.wait(left)
            return list(self.messages)

    def snapshot(self) -> list[Any]:
        """The messages so far."""
        with self._cond:
            return list(self.messages)

    def close(self) -> None:
        """Unsubscribe."""
        self._subscriber.unregister()


@pytest.fixture
def events(client_node: Any) -> Iterator[Callable[[], Recorder]]:
    """``events()``: a recorder of ``/rosmc/mission_events`` (connected to the server)."""
    made: list[Recorder] = []

    def make() -> Recorder:
        recorder = Recorder(interface.EVENTS_TOPIC, wire.MissionEvent)
        made.append(recorder)
        return recorder

    yield make
    for recorder in made:
        recorder.close()


# -- a robot's end of the link, played by the test -------------------------------------------
class FakeRobot:
    """Publishes what a robot's executor would on ``agent``'s link; records its commands."""

    def __init__(self, agent: str) -> None:
        self.agent = agent
        topics = interface.ground_link(agent)
        self.commands = Recorder(topics.command, wire.RobotCommand)
        self._snapshot = rospy.Publisher(topics.snapshot, wire.ExecutorSnapshot, queue_size=10)
        self._ack = rospy.Publisher(topics.ack, wire.RobotAck, queue_size=10)
        self._report = rospy.Publisher(topics.report, wire.RobotReport, queue_size=10)
        deadline = time.monotonic() + 30.0
        for publisher in (self._snapshot, self._ack, self._report):
            while publisher.get_num_connections() == 0:
                assert time.monotonic() < deadline, f"the server does not listen to {agent}"
                time.sleep(0.01)

    def announce(
        self, last_command_seq: int = 0, last_report_seq: int = 0, digest: str | None = None
    ) -> None:
        """Publish one executor snapshot: the ground then knows this robot (link UP).

        With ``digest``, the snapshot leaves its (empty) queue out and carries that digest.
        """
        self._snapshot.publish(
            wire.ExecutorSnapshot(
                agent=self.agent,
                stamp=rospy.Time.now(),
                last_command_seq=last_command_seq,
                last_report_seq=last_report_seq,
                state="idle",
                queue_omitted=digest is not None,
                status_digest=digest or "",
            )
        )

    def wait_command(self, kind: int, timeout: float = 5.0) -> wire.RobotCommand:
        """The first command of type ``kind`` received."""

        def has(messages: list[wire.RobotCommand]) -> bool:
            return any(m.type == kind for m in messages)

        return next(m for m in self.commands.wait_for(has, timeout) if m.type == kind)

    def ack(self, command: wire.RobotCommand, ids: list[str] | None = None) -> None:
        """Accept ``command`` (for the skills ``ids``, all of the command's by default)."""
        taken = ids if ids is not None else [s.id for s in command.skills] or command.skill_ids
        self._ack.publish(
            wire.RobotAck(
                agent=self.agent,
                seq=command.seq,
                stamp=rospy.Time.now(),
                result=wire.RobotAck.ACCEPTED,
                accepted_ids=list(taken),
            )
        )

    def report(self, seq: int, skill_id: str, status: int, attempt: int = 1) -> None:
        """Publish the robot's report number ``seq``: ``skill_id`` is now ``status``."""
        self._report.publish(
            wire.RobotReport(
                agent=self.agent,
                seq=seq,
                stamp=rospy.Time.now(),
                skill_id=skill_id,
                status=wire.SkillStatus(status),
                attempt=attempt,
            )
        )

    def close(self) -> None:
        """Stop listening and publishing."""
        self.commands.close()
        for publisher in (self._snapshot, self._ack, self._report):
            publisher.unregister()


@pytest.fixture
def fake_robot(client_node: Any) -> Iterator[Callable[[str], FakeRobot]]:
    """``fake_robot(agent)``: play ``agent``'s robot on its link (closed after the test)."""
    made: list[FakeRobot] = []

    def make(agent: str) -> FakeRobot:
        robot = FakeRobot(agent)
        made.append(robot)
        return robot

    yield make
    for robot in made:
        robot.close()
