"""Steering ``rosmc replay`` of the committed sample: pause, resume, seek, rate, keys.

The replay runs as a subprocess on the session's master, as a user starts it; this test
process steers it through ``<prefix>/rosmc/replay/control`` and subscribes as rviz, the
command GUI (a :class:`MissionFollower`, the GUIs' mirror) and a TF listener would. After
a seek every subscriber must hold the state at the target, taken from the recording
itself: the mission then, the newest agent states, site and score, and TF (stamps moved
forward after a seek back). In a terminal (a pty), keys steer it and the terminal gets
its mode back however the replay ends.
"""

from __future__ import annotations

import fcntl
import io
import os
import pty
import select
import signal
import subprocess
import sys
import termios
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rosmc.srv as wire_srv
import rospy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from rosmc_server import interface
from rosmc_server.conversions import mission_to_msg
from rosmc_server.recording import read_journal
from rosmc_server.recording.history import MissionHistory
from rosmc_server.recording.playback import Playlist
from rosmc_server.ros.client import MissionClient, MissionFollower
from tests.conftest import communicate_or_stacks, wait_until
from tests.integration.server_fixtures import Recorder
from tests.ros.recording_checks import SAMPLE, unstamped

pytest_plugins = ["tests.integration.server_fixtures"]

REPO = Path(__file__).resolve().parents[2]
ROSMC = REPO / "scripts" / "rosmc"
Request = wire_srv.ReplayControlRequest
STATE_TOPICS = {
    interface.AGENT_STATES_TOPIC: wire.AgentStates,
    interface.SCIENCE_TOPIC: wire.ScienceState,
    interface.WORLD_TOPIC: MarkerArray,
}


@pytest.fixture(scope="module")
def history() -> MissionHistory:
    return MissionHistory.from_journal(SAMPLE)


@pytest.fixture(scope="module")
def playlist(history: MissionHistory) -> Playlist:
    return Playlist(read_journal(SAMPLE).records, history.start)


Control = Callable[..., Any]


def start_replay(launch_process: Any, env: Any, prefix: str, *args: str) -> Control:
    """Start ``rosmc replay`` of the sample under ``prefix``; return a caller of its control."""
    launch_process(
        [sys.executable, str(ROSMC), "replay", str(SAMPLE), "--prefix", prefix, *args],
        env=env,
        name="replay",
    )
    name = interface.prefixed(interface.REPLAY_CONTROL_SERVICE, prefix)
    rospy.wait_for_service(name, timeout=30.0)
    proxy = rospy.ServiceProxy(name, wire_srv.ReplayControl)

    def control(command: int, **fields: Any) -> Any:
        return proxy(Request(command=command, **fields))

    return control


def recorders(prefix: str) -> dict[str, Recorder]:
    topics = {
        interface.MISSION_TOPIC: wire.Mission,
        interface.EVENTS_TOPIC: wire.MissionEvent,
        interface.TF_TOPIC: TFMessage,
        interface.REPLAY_STATE_TOPIC: wire.ReplayState,
        **STATE_TOPICS,
    }
    return {
        topic: Recorder(interface.prefixed(topic, prefix), msg_type)
        for topic, msg_type in topics.items()
    }


@pytest.fixture
def listen() -> Iterator[Callable[[str], dict[str, Recorder]]]:
    made: list[Recorder] = []

    def make(prefix: str) -> dict[str, Recorder]:
        found = recorders(prefix)
        made.extend(found.values())
        return found

    yield make
    for recorder in made:
        recorder.close()


def serialized(msg: Any) -> bytes:
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return buffer.getvalue()


def stamps(messages: list[Any]) -> list[int]:
    return [t.header.stamp.to_nsec() for m in messages for t in m.transforms]


def test_a_seek_back_leaves_every_subscriber_with_the_state_then(
    client_node: Any,
    launch_process: Any,
    listen: Callable[[str], dict[str, Recorder]],
    history: MissionHistory,
    playlist: Playlist,
) -> None:
    control = start_replay(launch_process, client_node.env, "/seek", "--rate", "2", "--hold")
    heard = listen("/seek")
    follower = MissionFollower(prefix="/seek", check_period=0.2)
    follower.start()
    client = MissionClient(10.0, prefix="/seek")
    try:
        late = 0.8 * history.duration
        assert control(Request.SEEK, time=late).success
        heard[interface.EVENTS_TOPIC].wait_for(lambda m: len(m) >= 2, timeout=30.0)
        paused = control(Request.PAUSE)
        assert paused.success and paused.state.paused
        # The GUIs' mirror is ahead of the target: the seek must take it back.
        wait_until(
            lambda: follower.mirror.revision == paused.state.revision,
            30.0,
            f"the follower's mirror reached revision {paused.state.revision}",
        )
        before = {topic: len(recorder.snapshot()) for topic, recorder in heard.items()}
        newest_tf = max(stamps(heard[interface.TF_TOPIC].snapshot()))

        target = 0.3 * history.duration
        moved = control(Request.SEEK, time=target)
        revision = history.revision_at(target).revision
        assert moved.success, moved.message
        assert (moved.state.position, moved.state.revision) == (target, revision)
        assert moved.state.paused and moved.state.seeks == 2
        expected = mission_to_msg(history.at_time(target).content(), revision, 0.0)

        def arrived(topic: str, wanted: Callable[[Any], bool]) -> Any:
            """Wait for a message after the seek that is ``wanted``; it must be the newest."""
            got = heard[topic].wait_for(lambda m: any(map(wanted, m[before[topic] :])), 30.0)
            assert wanted(got[-1]), f"{topic}: a later message followed the state at the seek"
            return got[-1]

        # The mission: the latched snapshot, get_mission, and the GUIs' mirror.
        arrived(interface.MISSION_TOPIC, lambda m: unstamped(m) == unstamped(expected))
        assert client.get_mission().content() == history.at_time(target).content()
        wait_until(
            lambda: follower.mirror.revision == revision,
            30.0,
            f"the follower's mirror went back to revision {revision}",
        )
        assert follower.mirror.state is not None
        assert follower.mirror.state.content() == history.at_time(target).content()
        # The robots, the site and the score as last recorded before the target.
        for topic in STATE_TOPICS:
            recorded = playlist.latest(topic, target)
            assert recorded is not None
            arrived(topic, lambda m, r=recorded: serialized(m) == serialized(r.message))
        # TF: the transforms then, stamped after everything published before the seek.
        recorded_tf = playlist.latest(interface.TF_TOPIC, target)
        assert recorded_tf is not None
        transforms = [t.transform for t in recorded_tf.message.transforms]
        tf = arrived(
            interface.TF_TOPIC, lambda m: [t.transform for t in m.transforms] == transforms
        )
        assert min(stamps([tf])) > newest_tf
        state = arrived(interface.REPLAY_STATE_TOPIC, lambda m: m.seeks == 2)
        assert (state.revision, state.paused, state.position) == (revision, True, target)

        # Playing on from there: the events that follow the target, in order.
        before[interface.EVENTS_TOPIC] = len(heard[interface.EVENTS_TOPIC].snapshot())
        assert control(Request.RESUME).success
        events = heard[interface.EVENTS_TOPIC].wait_for(
            lambda m: len(m) >= before[interface.EVENTS_TOPIC] + 3, 30.0
        )[before[interface.EVENTS_TOPIC] :]
        assert [int(e.revision) for e in events[:3]] == [revision + 1, revision + 2, revision + 3]
        later = stamps(heard[interface.TF_TOPIC].snapshot()[before[interface.TF_TOPIC] :])
        assert later == sorted(later), "TF stamps only go forward"
    finally:
        follower.close()
        client.close()


def test_pause_holds_everything_and_bad_requests_change_nothing(
    client_node: Any,
    launch_process: Any,
    listen: Callable[[str], dict[str, Recorder]],
    history: MissionHistory,
) -> None:
    control = start_replay(launch_process, client_node.env, "/pause", "--hold")
    heard = listen("/pause")
    events = heard[interface.EVENTS_TOPIC]
    events.wait_for(lambda m: len(m) >= 2, 30.0)
    paused = control(Request.PAUSE)
    assert paused.success and paused.state.paused and "paused" in paused.message
    time.sleep(0.3)  # a record due just before the pause may still be on its way
    count = len(events.snapshot())
    time.sleep(1.0)  # nothing may happen while paused
    assert len(events.snapshot()) == count
    state = control(Request.STATE).state
    assert (state.position, state.paused) == (paused.state.position, True)
    for request in (
        Request(command=Request.SET_RATE, rate=0.0),
        Request(command=Request.SEEK, time=float("nan")),
        Request(command=99),
    ):
        refused = control(request.command, time=request.time, rate=request.rate)
        assert not refused.success and refused.message and "\n" not in refused.message
        assert refused.state.position == paused.state.position and refused.state.paused
    faster = control(Request.SET_RATE, rate=8.0)
    assert faster.success and faster.state.rate == 8.0
    assert control(Request.RESUME).success
    events.wait_for(lambda m: len(m) > count, 30.0)
    # At the end a held replay stays; resuming plays it again from the start.
    wait_until(lambda: control(Request.STATE).state.ended, 30.0, "the replay reached the end")
    again = control(Request.RESUME)
    assert again.success and again.state.position < history.duration / 2
    assert again.state.revision == history.revision_at(again.state.position).revision


def test_without_a_terminal_progress_is_printed_sparsely(client_node: Any) -> None:
    done = subprocess.run(
        [sys.executable, str(ROSMC), "replay", str(SAMPLE), "--rate", "10", "--prefix", "/plain"],
        env=dict(client_node.env),
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    progress = [line for line in done.stdout.splitlines() if line.endswith(" --")]
    assert progress[0].startswith("[    0.00 s] --     0.00 / ")
    assert "end" in progress[-1]
    # Every 10 s of recording time, and the end: no redrawing escapes in a pipe.
    assert len(progress) <= SAMPLE_PROGRESS_LINES
    assert "\x1b" not in done.stdout and "\r" not in done.stdout
    assert "replay done at revision" in done.stdout


SAMPLE_PROGRESS_LINES = 4


class Terminal:
    """``rosmc replay`` on a pseudo-terminal, as a user runs it."""

    def __init__(self, env: Any, *args: str) -> None:
        self.master, self.slave = pty.openpty()
        self.mode = termios.tcgetattr(self.slave)
        self.output = b""
        self.process = subprocess.Popen(
            [sys.executable, str(ROSMC), "replay", str(SAMPLE), *args],
            env=dict(env),
            stdin=self.slave,
            stdout=self.slave,
            stderr=self.slave,
            start_new_session=True,
        )

    def read_until(self, text: str, timeout: float = 30.0) -> str:
        """Read the terminal until ``text`` shows; return everything shown so far."""
        deadline = time.monotonic() + timeout
        while text.encode() not in self.output:
            assert time.monotonic() < deadline, f"no {text!r} in {self.output[-2000:]!r}"
            ready, _, _ = select.select([self.master], [], [], 0.1)
            if ready:
                self.output += os.read(self.master, 65536)
        return self.output.decode(errors="replace")

    def press(self, keys: bytes) -> None:
        os.write(self.master, keys)

    def cbreak(self) -> bool:
        return not termios.tcgetattr(self.slave)[3] & termios.ICANON

    def close(self, timeout: float = 30.0) -> int:
        """Wait for the replay to end, reading the terminal meanwhile (a terminal nobody
        reads fills up, and then the replay blocks on its next write)."""
        deadline = time.monotonic() + timeout
        while self.process.poll() is None and time.monotonic() < deadline:
            self._read(deadline)
        communicate_or_stacks(self.process, 1.0, output=self._screen)
        self._read(time.monotonic() + 1.0)
        return self.process.returncode

    def _read(self, until: float) -> None:
        """Add what the terminal shows to ``output`` until nothing comes for 0.1 s (or
        ``until``)."""
        while time.monotonic() < until and select.select([self.master], [], [], 0.1)[0]:
            try:
                self.output += os.read(self.master, 65536)
            except OSError:  # the replay closed the terminal: nothing more to read
                return

    def _screen(self) -> str:
        """Everything the terminal showed, with what was still to be read."""
        self._read(time.monotonic() + 1.0)
        return self.output.decode(errors="replace")

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait(10.0)
        for fd in (self.master, self.slave):
            os.close(fd)


@pytest.fixture
def terminal(client_node: Any) -> Iterator[Callable[..., Terminal]]:
    made: list[Terminal] = []

    def make(*args: str) -> Terminal:
        made.append(Terminal(client_node.env, *args))
        return made[-1]

    yield make
    for term in made:
        term.kill()


def test_keys_steer_the_replay_in_a_terminal(
    terminal: Callable[..., Terminal], history: MissionHistory
) -> None:
    term = terminal("--prefix", "/keys", "--rate", "0.5")
    term.read_until("x  playing")
    assert term.cbreak(), "keys arrive one by one, unechoed"
    rospy.wait_for_service("/keys/rosmc/replay/control", timeout=30.0)
    proxy = rospy.ServiceProxy("/keys/rosmc/replay/control", wire_srv.ReplayControl)

    def state() -> Any:
        return proxy(Request(command=Request.STATE)).state

    term.press(b" ")
    term.read_until("paused")
    assert state().paused
    start = state().position
    term.press(b"\x1b[C")  # right arrow: 10 s on
    wait_until(lambda: state().seeks == 1, 30.0, "the right arrow moved the replay")
    ahead = min(start + 10.0, history.duration)
    assert state().position == pytest.approx(ahead) and state().paused
    term.press(b"\x1b[D")  # left arrow: 10 s back
    wait_until(lambda: state().seeks == 2, 30.0, "the left arrow moved the replay")
    assert state().position == pytest.approx(max(ahead - 10.0, 0.0))
    term.press(b"]")
    wait_until(lambda: state().rate == 1.0, 30.0, "] doubled the rate")
    term.read_until("1x  paused")
    term.press(b"q")
    assert term.close() == 0
    shown = term.output.decode(errors="replace")
    assert "\r\x1b[K" in shown and "replay done at revision" in shown
    assert termios.tcgetattr(term.slave) == term.mode, "the terminal's mode is back"


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_the_terminal_gets_its_mode_back_when_the_replay_is_stopped(
    terminal: Callable[..., Terminal], sig: signal.Signals
) -> None:
    term = terminal("--prefix", f"/stop{int(sig)}", "--rate", "0.5")
    term.read_until("x  playing")
    assert term.cbreak()
    os.killpg(term.process.pid, sig)
    code = term.close()
    assert code in (0, 130), term.output[-2000:]
    assert termios.tcgetattr(term.slave) == term.mode, "the terminal's mode is back"


def test_in_the_background_of_a_terminal_it_leaves_the_terminal_alone(
    client_node: Any, tmp_path: Path
) -> None:
    # `rosmc replay ... &` in an interactive shell: changing the terminal's mode from the
    # background would stop the job (SIGTTOU); it must play to the end without keys.
    master, slave = pty.openpty()
    log = tmp_path / "replay.log"
    command = (
        f"set -m; {sys.executable} {ROSMC} replay {SAMPLE} --rate 10 --prefix /bg "
        f"> {log} 2>&1 & wait %1; jobs -l"
    )

    def controlling_terminal() -> None:  # as a login shell gets its terminal
        fcntl.ioctl(0, termios.TIOCSCTTY, 0)

    shell = subprocess.Popen(
        ["bash", "-c", command],
        env=dict(client_node.env),
        stdin=slave,
        stdout=slave,
        stderr=slave,
        start_new_session=True,
        preexec_fn=controlling_terminal,
    )
    try:
        assert shell.wait(60.0) == 0
        jobs = b""
        while select.select([master], [], [], 0.1)[0]:
            jobs += os.read(master, 65536)
        assert b"Stopped" not in jobs, jobs
        assert "replay done at revision" in log.read_text(), log.read_text()[-2000:]
    finally:
        if shell.poll() is None:
            os.killpg(shell.pid, signal.SIGKILL)
        os.close(master)
        os.close(slave)
