"""Fixtures shared by every test tier.

Tiers: ``tests/unit`` (pure Python, no ROS), ``tests/ros`` (generated messages, no master),
``tests/integration`` (real ROS tools and a real ``rosmaster``). Run through ``make test``
or, after ``source env.sh``, plain ``python -m pytest``.

``ros_master``
    One real ``rosmaster --core`` per test session on a free loopback port, with a private
    ``ROS_HOME``. ``ros_master.env`` is the environment for node subprocesses; the fixture
    also points this process's ``ROS_MASTER_URI`` at it for in-process rospy use.
``launch_process``
    Starts a process (a node, ``roslaunch``, a CLI) with its output in a log file, and stops
    it, with all of its children, when the test ends.

:func:`wait_until` is how every tier waits for something to happen: it polls a condition
instead of sleeping for a fixed time (a test that sleeps is slow on a fast machine and
flaky on a loaded one). A fixed sleep is left only where a test checks that nothing
happens for a while. Tests assert order and outcome, never how long something took: the
figures are in ``bench/``, and every deadline is one that only something stuck misses.

Hypothesis profiles, chosen with ``HYPOTHESIS_PROFILE`` (default ``quick``):
``quick`` (what ``make test`` runs: few examples, no deadline) and ``thorough`` (many
examples, ``make test-thorough``). Property tests that name no example count take it from
the profile.
"""

from __future__ import annotations

import contextlib
import faulthandler
import os
import signal
import socket
import subprocess
import sys
import threading
import time
import traceback
import xmlrpc.client
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any, TypeVar

import pytest
from hypothesis import HealthCheck, settings

REPO_ROOT = Path(__file__).resolve().parent.parent
T = TypeVar("T")
LOOPBACK = "127.0.0.1"
MASTER_START_TIMEOUT = 60.0
STOP_TIMEOUT = 30.0
# After the last test, the interpreter must exit within this time: a thread still running
# (a worker stuck in a call, a timer that re-arms itself) would otherwise hold the run open
# until CI's own limit. Its stack is printed, and the run ends with a failure.
EXIT_GRACE = 120.0
HYPOTHESIS_PROFILES = MappingProxyType(
    {
        "quick": settings(max_examples=100, deadline=None, print_blob=True),
        "thorough": settings(
            max_examples=3000,
            deadline=None,
            print_blob=True,
            suppress_health_check=[HealthCheck.too_slow],
        ),
    }
)


def pytest_configure(config: pytest.Config) -> None:
    """Load the hypothesis profile that ``HYPOTHESIS_PROFILE`` names (``quick`` by default)."""
    name = os.environ.get("HYPOTHESIS_PROFILE", "quick")
    if name not in HYPOTHESIS_PROFILES:
        known = ", ".join(sorted(HYPOTHESIS_PROFILES))
        raise pytest.UsageError(f"HYPOTHESIS_PROFILE={name!r} is not one of: {known}")
    for profile, chosen in HYPOTHESIS_PROFILES.items():
        settings.register_profile(profile, chosen)
    settings.load_profile(name)
    # A suite started as a background job of a non-interactive shell (`cmd &` in a script,
    # nohup) inherits SIGINT ignored, and so would every process it starts: the tests'
    # Ctrl-C would go unheard, and stopping a launch (SIGINT first) would wait for SIGKILL.
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_unconfigure(config: pytest.Config) -> None:
    """Name every thread that would keep the interpreter from exiting, with its stack.

    Such a thread is a leak of the code under test (a mission client not closed, a timer
    chain): it is reported here, and if the process still runs ``EXIT_GRACE`` seconds later
    every stack is dumped and the process exits with status 1.
    """
    frames = sys._current_frames()
    lingering = [
        thread
        for thread in threading.enumerate()
        if thread is not threading.main_thread() and not thread.daemon and thread.is_alive()
    ]
    for thread in lingering:
        stack = (
            "".join(traceback.format_stack(frames[thread.ident])) if thread.ident in frames else ""
        )
        sys.stderr.write(f"\nthread still running after the tests: {thread.name}\n{stack}")
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        # A pytest-xdist worker stays up after its last test until the whole run ends, so
        # only the process that runs the session itself is held to the grace period.
        faulthandler.dump_traceback_later(EXIT_GRACE, exit=True)


def wait_until(
    condition: Callable[[], T | None],
    timeout: float,
    what: str,
    period: float = 0.02,
    pause: Callable[[float], object] = time.sleep,
) -> T:
    """Poll ``condition`` every ``period`` seconds until it returns something true; return it.

    ``pause`` waits between polls: a Qt test passes one that runs the event loop meanwhile
    (:func:`qt_pause`), so the widget under test keeps working while the test waits.

    Raises:
        AssertionError: ``timeout`` seconds passed first (the message says ``what``).
    """
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:g} s waiting until {what}")
        pause(period)


def qt_pause(seconds: float) -> None:
    """Run the Qt event loop for ``seconds`` (a ``pause`` for :func:`wait_until`)."""
    from python_qt_binding.QtTest import QTest

    QTest.qWait(max(1, round(seconds * 1000)))


def free_port() -> int:
    """A TCP port on the loopback interface that nothing listens on right now."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind((LOOPBACK, 0))
        port: int = sock.getsockname()[1]
        return port


def master_answers(uri: str) -> bool:
    """Whether a ROS master at ``uri`` answers ``getSystemState``."""
    proxy = xmlrpc.client.ServerProxy(uri)
    try:
        code, _, _ = proxy.getSystemState("/pytest")
    except (OSError, xmlrpc.client.Error):
        return False
    return bool(code == 1)


def stop_process(process: subprocess.Popen[bytes], timeout: float = STOP_TIMEOUT) -> None:
    """Stop ``process`` and its process group: SIGINT (as roslaunch expects), then SIGKILL.

    The process must have been started with ``start_new_session=True``.
    """
    if process.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGINT)
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(timeout)
    # Children that outlived their parent go too.
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(timeout)


def communicate_or_stacks(
    process: subprocess.Popen[Any], timeout: float = 30.0, output: Callable[[], str] | None = None
) -> tuple[Any, Any]:
    """``process.communicate(timeout)``; if it is still running after ``timeout`` s, it is
    asked for every thread's stack (SIGUSR1: the entry scripts' faulthandler hook writes
    them to its stderr), killed, and the test fails with the end of its stderr (or of
    ``output()``, e.g. a terminal's screen): a hang at exit then says where it hangs.
    """
    try:
        return process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            process.send_signal(signal.SIGUSR1)
        time.sleep(1.0)  # written from a signal handler: a moment is enough
        with contextlib.suppress(ProcessLookupError):
            process.kill()
        _, err = process.communicate()
        written = output() if output is not None else str(err or "")
        raise AssertionError(
            f"{process.args} still ran {timeout:g} s after it was told to stop; it wrote "
            f"last:\n{written[-6000:]}"
        ) from None


def log_tail(path: Path, lines: int = 40) -> str:
    """The last ``lines`` lines of a log file, for failure messages."""
    try:
        text = path.read_text(errors="replace")
    except OSError:
        return f"<no log at {path}>"
    return "\n".join(text.splitlines()[-lines:])


@dataclass(frozen=True)
class RosMaster:
    """A running ``rosmaster`` that the tests share.

    Attributes:
        uri: ``http://127.0.0.1:PORT/`` of the master.
        port: Its TCP port.
        env: The environment for subprocesses that should talk to this master.
        home: Its private ``ROS_HOME`` (logs under ``home / "log"``).
    """

    uri: str
    port: int
    env: Mapping[str, str]
    home: Path

    def proxy(self) -> xmlrpc.client.ServerProxy:
        """A fresh XML-RPC proxy of the master API."""
        return xmlrpc.client.ServerProxy(self.uri)


def _master_env(uri: str, home: Path) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("ROS_HOSTNAME", None)  # would win over ROS_IP
    env.update(
        ROS_MASTER_URI=uri,
        ROS_IP=LOOPBACK,
        ROS_HOME=str(home),
        ROS_LOG_DIR=str(home / "log"),
        PYTHONUNBUFFERED="1",
    )
    return env


@pytest.fixture(scope="session")
def ros_master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RosMaster]:
    """A real ``rosmaster --core`` on a free loopback port, for the whole session."""
    home = tmp_path_factory.mktemp("ros_home")
    (home / "log").mkdir()
    failures = []
    for _attempt in range(3):  # the free port may be taken before the master binds it
        port = free_port()
        uri = f"http://{LOOPBACK}:{port}/"
        env = _master_env(uri, home)
        log_path = home / f"rosmaster-{port}.log"
        with log_path.open("wb") as log:
            process = subprocess.Popen(
                ["rosmaster", "--core", "-p", str(port)],
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        deadline = time.monotonic() + MASTER_START_TIMEOUT
        while process.poll() is None and time.monotonic() < deadline:
            if master_answers(uri):
                break
            time.sleep(0.05)
        if process.poll() is None and master_answers(uri):
            break
        stop_process(process)
        failures.append(f"port {port}:\n{log_tail(log_path)}")
    else:
        pytest.fail("rosmaster did not start:\n" + "\n".join(failures))

    master = RosMaster(uri=uri, port=port, env=env, home=home)
    with pytest.MonkeyPatch.context() as patch:
        for name in ("ROS_MASTER_URI", "ROS_IP", "ROS_HOME", "ROS_LOG_DIR"):
            patch.setenv(name, env[name])
        patch.delenv("ROS_HOSTNAME", raising=False)
        try:
            yield master
        finally:
            stop_process(process)


class LoggedProcess(subprocess.Popen[bytes]):
    """A ``Popen`` whose stdout and stderr go to ``log_path``."""

    log_path: Path

    def log(self) -> str:
        """Everything the process printed so far."""
        return self.log_path.read_text(errors="replace")


LaunchProcess = Callable[..., LoggedProcess]


@pytest.fixture
def launch_process(tmp_path: Path) -> Iterator[LaunchProcess]:
    """Start processes that are stopped (with their children) when the test ends.

    Call it as ``launch_process(argv, env=None, name=None, cwd=None)``; ``env`` defaults to
    this process's environment (pass ``ros_master.env`` for nodes). Returns the
    :class:`LoggedProcess`. A process's log tail is printed at teardown, so a failing test
    shows what its nodes said.
    """
    started: list[LoggedProcess] = []

    def launch(
        argv: Sequence[str],
        env: Mapping[str, str] | None = None,
        name: str | None = None,
        cwd: Path | None = None,
    ) -> LoggedProcess:
        label = name or Path(argv[0]).name
        log_path = tmp_path / f"{len(started):02d}-{label}.log"
        with log_path.open("wb") as log:
            process = LoggedProcess(
                list(argv),
                env=dict(env if env is not None else os.environ),
                cwd=cwd,
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        process.log_path = log_path
        started.append(process)
        return process

    yield launch

    for process in reversed(started):
        stop_process(process)
        print(f"--- {process.log_path.name} (exit {process.returncode}) ---")
        print(log_tail(process.log_path))
