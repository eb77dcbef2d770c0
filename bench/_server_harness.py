"""What the mission-server benchmarks share (bench_server.py, bench_scale.py and others).

A private ``rosmaster`` on a free loopback port, a real ``mission_server`` process (optionally
under cProfile; its CPU time, memory and logged load phases), persistent service proxies with
an event recorder, a proxy that keeps an answer's bytes undecoded, percentiles (generated
libraries and mission documents are in ``_missions.py``), and :func:`stop_process`, which
stops a process whatever its signal disposition: a benchmark started with SIGINT ignored
(``nohup``, a background job of a script, some CI shells) passes that on to every process it
starts, and a ``rosmaster`` that ignores SIGINT would otherwise be waited for until the
benchmark is killed, with its figures unprinted.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import xmlrpc.client
from collections.abc import Iterator, Sequence
from pathlib import Path
from types import FrameType
from typing import Any

REPO = Path(__file__).resolve().parents[1]
LOOPBACK = "127.0.0.1"
# The server's log line of a load (rosmc_server/ros/whole_mission.py), its phases in ms.
LOAD_PHASES = re.compile(
    r"read and checked in (\d+) ms, serialized in (\d+) ms, applied and journaled in (\d+) ms"
)

# Runs the server script with a cProfile profiler in every thread (rospy serves each
# connection on its own thread); SIGUSR1 writes the merged statistics and exits.
PROFILED_SERVER = """
import cProfile, os, pstats, runpy, signal, sys, threading
profiles = [cProfile.Profile()]
def start_thread_profile(frame, event, arg):
    sys.setprofile(None)
    profile = cProfile.Profile()
    profiles.append(profile)
    profile.enable()
def dump(*_):
    stats = pstats.Stats(profiles[0])
    for profile in profiles[1:]:
        stats.add(profile)
    stats.dump_stats(os.environ["BENCH_PROFILE"])
    os._exit(0)
signal.signal(signal.SIGUSR1, dump)
threading.setprofile(start_thread_profile)
sys.argv = sys.argv[1:]
profiles[0].enable()
runpy.run_path(sys.argv[0], run_name="__main__")
"""


# -- processes ---------------------------------------------------------------------------------
@contextlib.contextmanager
def figures_printed(figures: dict[str, Any]) -> Iterator[dict[str, Any]]:
    """Print ``figures`` as one JSON object when the block ends, however it ends.

    Fill ``figures`` as results come in. An error, Ctrl-C or SIGTERM (``run_all.py``'s
    timeout sends it first) ends the block early: what was measured so far is printed
    with ``interrupted`` saying why, after the processes the block started are stopped.
    """

    def terminate(signum: int, frame: FrameType | None) -> None:
        raise SystemExit(128 + signum)

    previous = signal.signal(signal.SIGTERM, terminate)
    try:
        yield figures
    except BaseException as error:
        figures["interrupted"] = f"{type(error).__name__}: {error}"
        raise
    finally:
        signal.signal(signal.SIGTERM, previous)
        print(json.dumps(figures, indent=2), flush=True)


def free_port() -> int:
    """A TCP port nobody listens on now, on the loopback address."""
    with socket.socket() as sock:
        sock.bind((LOOPBACK, 0))
        return int(sock.getsockname()[1])


def stop_process(
    process: subprocess.Popen[Any], first: int = signal.SIGINT, grace: float = 10.0
) -> None:
    """Stop ``process`` (and its group, if it leads one): ``first``, SIGTERM, then SIGKILL.

    Each signal gets its time to work before the next is sent; nothing here raises, so
    whatever follows (printing the figures) still runs.
    """
    for signum, wait in ((first, grace), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        if process.poll() is not None:
            break
        _signal(process, signum)
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(wait)
    _signal(process, signal.SIGKILL)  # what it started and left behind in its group


def _signal(process: subprocess.Popen[Any], signum: int) -> None:
    with contextlib.suppress(ProcessLookupError, PermissionError):
        if os.getpgid(process.pid) == process.pid:
            os.killpg(process.pid, signum)
        elif process.poll() is None:
            process.send_signal(signum)


@contextlib.contextmanager
def bench_node(prefix: str, name: str) -> Iterator[tuple[Path, dict[str, str]]]:
    """A private rosmaster in a new temporary folder, and this process a node ``name`` of it.

    Yields the folder (removed afterwards) and the environment for other nodes.
    """
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        base = Path(tmp)
        (base / "log").mkdir()
        with ros_master(base) as env:
            import rospy

            rospy.init_node(name, anonymous=True, disable_signals=True)
            try:
                yield base, env
            finally:
                rospy.signal_shutdown("done")


@contextlib.contextmanager
def ros_master(home: Path) -> Iterator[dict[str, str]]:
    """A private rosmaster; yields the environment for nodes (this process uses it too)."""
    port = free_port()
    env = dict(os.environ)
    env.pop("ROS_HOSTNAME", None)
    env.update(
        ROS_MASTER_URI=f"http://{LOOPBACK}:{port}/",
        ROS_IP=LOOPBACK,
        ROS_HOME=str(home),
        ROS_LOG_DIR=str(home / "log"),
        PYTHONUNBUFFERED="1",
    )
    os.environ.update({k: env[k] for k in ("ROS_MASTER_URI", "ROS_IP", "ROS_HOME", "ROS_LOG_DIR")})
    (home / "log").mkdir(parents=True, exist_ok=True)
    with (home / "rosmaster.log").open("wb") as log:
        master = subprocess.Popen(
            ["rosmaster", "--core", "-p", str(port)],
            env=env,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    master_api = xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"])
    try:
        deadline = time.monotonic() + 20
        while True:
            with contextlib.suppress(OSError, xmlrpc.client.Error):
                if master_api.getSystemState("/bench")[0] == 1:
                    break
            if time.monotonic() > deadline:
                raise RuntimeError("rosmaster did not start")
            time.sleep(0.05)
        yield env
    finally:
        stop_process(master, grace=5.0)


class Server:
    """A mission_server process (optionally under cProfile, stopped with SIGUSR1 then)."""

    def __init__(
        self,
        env: dict[str, str],
        work: Path,
        library: Path,
        profile: Path | None,
        params: Sequence[str] = (),
        repo: Path = REPO,
    ):
        """Start the server of the checkout at ``repo`` (another checkout: a baseline)."""
        self.journal_dir = work / "journal"
        self.mission_dir = work / "missions"  # where SaveMission and LoadMission take paths
        self.profiled = profile is not None
        argv = [
            str(repo / "scripts" / "mission_server"),
            f"_library:={library}",
            f"_journal_dir:={self.journal_dir}",
            f"_mission_dir:={self.mission_dir}",
            *params,
        ]
        env = dict(env)
        if repo != REPO:
            env["PYTHONPATH"] = os.pathsep.join([str(repo), env.get("PYTHONPATH", "")])
        if profile is not None:
            env["BENCH_PROFILE"] = str(profile)
            argv = ["-c", PROFILED_SERVER, *argv]
        self.log_path = work / "server.log"
        with self.log_path.open("wb") as log:
            self.process = subprocess.Popen(
                [sys.executable, *argv],
                env=env,
                cwd=repo,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        deadline = time.monotonic() + 60
        while "mission server ready" not in self.log_path.read_text(errors="replace"):
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise RuntimeError(f"server did not start:\n{self.log_path.read_text()[-3000:]}")
            time.sleep(0.05)

    def peak_rss_mib(self) -> float:
        """The server's peak resident memory so far."""
        return self._status_mib("VmHWM")

    def rss_mib(self) -> float:
        """The server's resident memory now."""
        return self._status_mib("VmRSS")

    def _status_mib(self, field: str) -> float:
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith(f"{field}:"):
                return round(int(line.split()[1]) / 1024, 1)
        return -1.0

    def cpu_seconds(self) -> float:
        """User and system CPU time the server has used so far (all its threads)."""
        stat = Path(f"/proc/{self.process.pid}/stat").read_text()
        fields = stat.rsplit(")", 1)[1].split()  # after the command name, which may hold spaces
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def load_phases(self) -> list[tuple[float, float, float]]:
        """Per load, as the server logs it: ms reading and checking, serializing, applying.

        Empty for a server that does not log them.
        """
        text = self.log_path.read_text(errors="replace")
        return [(float(a), float(b), float(c)) for a, b, c in LOAD_PHASES.findall(text)]

    def journal_bytes(self) -> int:
        """Bytes in the server's journal files."""
        return sum(p.stat().st_size for p in self.journal_dir.glob("*.mcap"))

    def stop(self, profiled: bool | None = None) -> None:
        """Stop the server (a profiled one writes its statistics first)."""
        profiled = self.profiled if profiled is None else profiled
        stop_process(self.process, signal.SIGUSR1 if profiled else signal.SIGINT, grace=30.0)


# -- measuring -------------------------------------------------------------------------------------
def percentiles(samples: list[float]) -> dict[str, float]:
    """Median and p95 of durations in seconds, in milliseconds, and the sample count."""
    ordered = sorted(samples)
    p95 = ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]
    return {
        "p50_ms": round(statistics.median(ordered) * 1000, 3),
        "p95_ms": round(p95 * 1000, 3),
        "n": len(ordered),
    }


def raw_proxy(operation: str) -> Any:
    """A persistent proxy of an operator service whose answers keep their bytes undecoded.

    ``call`` returns an object with the answer's bytes in ``raw``: it times the server and
    the transport alone, without the client decoding the answer into genpy messages.
    """
    import rosmc.srv as srv
    import rospy

    from rosmc_server import interface

    service = getattr(srv, interface.SERVICES[operation])

    class RawResponse(service._response_class):  # type: ignore[misc,name-defined]
        def deserialize(self, data: bytes) -> Any:
            self.raw = bytes(data)
            return self

    class RawService:
        _type = service._type
        _md5sum = service._md5sum
        _request_class = service._request_class
        _response_class = RawResponse

    return rospy.ServiceProxy(interface.service_name(operation), RawService, persistent=True)


def serialized_size(msg: Any) -> int:
    """Bytes of a ROS message on the wire."""
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return len(buffer.getvalue())


class ServerClient:
    """Persistent proxies of every operator service, and the events the server publishes.

    ``get_mission_core`` is GetMission read as ``MissionClient`` reads it (core objects,
    no genpy messages); ``get_mission`` answers with genpy messages.

    Needs an initialized rospy node. ``rev`` follows the revision of every answer.
    """

    def __init__(self) -> None:
        import rosmc.msg as wire
        import rosmc.srv as srv
        import rospy

        from rosmc_server import interface
        from rosmc_server.conversions.task_memory import TaskMemory
        from rosmc_server.conversions.unpacking import remembering_get_mission

        self.wire, self.rospy = wire, rospy
        self.proxies: dict[str, Any] = {}
        for operation, type_name in interface.SERVICES.items():
            rospy.wait_for_service(interface.service_name(operation), 30)
            self.proxies[operation] = rospy.ServiceProxy(
                interface.service_name(operation), getattr(srv, type_name), persistent=True
            )
        # GetMission as the project's client reads it: straight into core objects, the
        # skills of records unchanged since its last answer taken from that answer.
        self.proxies["get_mission_core"] = rospy.ServiceProxy(
            interface.service_name("get_mission"),
            remembering_get_mission(TaskMemory()),
            persistent=True,
        )
        self.events: list[Any] = []
        self._lock = threading.Lock()
        self.subscriber = rospy.Subscriber(
            interface.EVENTS_TOPIC, wire.MissionEvent, self._on_event, queue_size=100000
        )
        self.rev = self.call("get_mission").mission.revision
        self.changes = 0

    def _on_event(self, msg: Any) -> None:
        with self._lock:
            self.events.append(msg)

    def call(self, operation: str, **fields: Any) -> Any:
        """Call a service; a refusal raises RuntimeError."""
        return self.timed(operation, **fields)[1]

    def timed(self, operation: str, **fields: Any) -> tuple[float, Any]:
        """Call a service; (seconds from request to answer, the answer)."""
        proxy = self.proxies[operation]
        request = proxy.request_class(**fields)
        started = time.perf_counter()
        response = proxy.call(request)
        elapsed = time.perf_counter() - started
        if getattr(response, "error_code", 0):
            raise RuntimeError(f"{operation} failed: {response.error}")
        if hasattr(response, "revision") and response.revision != self.rev:
            self.rev = response.revision
            self.changes += 1
        return elapsed, response

    def event_bytes(self, kinds: dict[int, str]) -> dict[str, int]:
        """The median serialized size of the events received, per name of their kind."""
        sizes: dict[str, list[int]] = {}
        with self._lock:
            events = list(self.events)
        for event in events:
            if event.kind in kinds:
                sizes.setdefault(kinds[event.kind], []).append(serialized_size(event))
        return {name: int(statistics.median(values)) for name, values in sizes.items()}

    def close(self) -> None:
        """Close the proxies and the subscription."""
        self.subscriber.unregister()
        for proxy in self.proxies.values():
            proxy.close()
