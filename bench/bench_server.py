"""Benchmark of the mission server's operator services; prints one JSON object.

Starts its own ``rosmaster`` on a free loopback port and, per mission size (agents x
skills per agent), a real ``mission_server`` on a generated library of that many dynamic
agents. The mission is loaded as one document, then each operation is timed from a
client with persistent service proxies: median and p95 latency of add, edit, delete,
reorder, add barrier, marker move, synchronize and get_mission; bytes per event, per
snapshot and per journaled change; the server's peak RSS. Then the whole-mission paths
(``whole``): get_mission right after a change and again at the same revision (decoded by
genpy, and as raw bytes: the server and transport alone), save to a path on the server and
save returning the document (each right after a change), and loading the mission the
server saved (also as the server's CPU time, which other work on the machine inflates
less than the wall time), ``--whole-repeats`` times each, median and max.
Run from the repository root::

    source env.sh
    python bench/bench_server.py [--sizes 2x10,5x100,20x500] [--samples 300] [--profile]
    python bench/bench_server.py --sizes 2x500,10x500,20x500 --samples 0 --cpu-seconds 30

``--samples 0`` skips the per-change operations. ``--cpu-seconds N`` measures, at the
largest size, the server's CPU time over N s of 10 changes/s without and then with a
subscriber to the latched ``/rosmc/mission``. ``--profile`` runs the largest size a
second time under cProfile (every server thread) and adds the top functions by internal
time to the output.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import pstats
import random
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
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

LOOPBACK = "127.0.0.1"
TARGET = {"p50_ms": 2.0, "p95_ms": 5.0}

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
def free_port() -> int:
    with socket.socket() as sock:
        sock.bind((LOOPBACK, 0))
        return int(sock.getsockname()[1])


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
    log = (home / "rosmaster.log").open("wb")
    master = subprocess.Popen(
        ["rosmaster", "--core", "-p", str(port)],
        env=env,
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 20
        while True:
            with contextlib.suppress(OSError):
                xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"]).getSystemState("/bench")
                break
            if time.monotonic() > deadline:
                raise RuntimeError("rosmaster did not start")
            time.sleep(0.05)
        yield env
    finally:
        # SIGINT may be ignored where the benchmark runs (a CI shell, nohup): then SIGKILL,
        # so that the figures are still printed.
        os.killpg(master.pid, signal.SIGINT)
        try:
            master.wait(5)
        except subprocess.TimeoutExpired:
            os.killpg(master.pid, signal.SIGKILL)
            master.wait(5)


class Server:
    """A mission_server process (optionally under cProfile)."""

    def __init__(self, env: dict[str, str], work: Path, library: Path, profile: Path | None):
        self.journal_dir = work / "journal"
        argv = [
            str(REPO / "scripts" / "mission_server"),
            f"_library:={library}",
            f"_journal_dir:={self.journal_dir}",
            f"_mission_dir:={work / 'missions'}",
        ]
        env = dict(env)
        if profile is not None:
            env["BENCH_PROFILE"] = str(profile)
            argv = ["-c", PROFILED_SERVER, *argv]
        self.log_path = work / "server.log"
        with self.log_path.open("wb") as log:
            self.process = subprocess.Popen(
                [sys.executable, *argv],
                env=env,
                cwd=REPO,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        deadline = time.monotonic() + 60
        while "mission server ready" not in self.log_path.read_text(errors="replace"):
            if self.process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"server did not start:\n{self.log_path.read_text()[-3000:]}")
            time.sleep(0.05)

    def cpu_seconds(self) -> float:
        """User and system CPU time the server has used so far."""
        fields = Path(f"/proc/{self.process.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def rss_mib(self) -> float:
        """The server's resident memory now."""
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return round(int(line.split()[1]) / 1024, 1)
        return -1.0

    def peak_rss_mib(self) -> float:
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return round(int(line.split()[1]) / 1024, 1)
        return -1.0

    def load_phases(self) -> list[tuple[float, ...]]:
        """Per load, as the server logs it: ms reading and checking, serializing, applying."""
        pattern = re.compile(
            r"read and checked in (\d+) ms, serialized in (\d+) ms, "
            r"applied and journaled in (\d+) ms"
        )
        text = self.log_path.read_text(errors="replace")
        return [tuple(float(x) for x in match.groups()) for match in pattern.finditer(text)]

    def journal_bytes(self) -> int:
        return sum(p.stat().st_size for p in self.journal_dir.glob("*.mcap"))

    def stop(self, profiled: bool = False) -> None:
        os.killpg(self.process.pid, signal.SIGUSR1 if profiled else signal.SIGINT)
        try:
            self.process.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait(10)


# -- the benchmark mission ------------------------------------------------------------------------
def agent_name(index: int) -> str:
    return f"robot_{index:02d}"


def library_yaml(agents: int) -> str:
    """A library of ``agents`` dynamic agents of one model with typical skills."""
    skills = {
        "move": {
            "duration": 60,
            "parameters": {
                "target": {"type": "pose", "default": {"x": 0.0, "y": 0.0}, "marker": "pose"},
                "speed": {"type": "float", "default": 0.5, "min": 0.05, "max": 2.0},
            },
        },
        "inspect": {
            "duration": 30,
            "parameters": {
                "radius": {"type": "float", "default": 2.0, "min": 0.5, "max": 10.0},
                "mode": {
                    "type": "string",
                    "default": "standard",
                    "choices": ["quick", "standard", "detailed"],
                },
                "tries": {"type": "int", "default": 1, "min": 1, "max": 5},
            },
        },
        "wait": {"duration": 10, "parameters": {"seconds": {"type": "float", "default": 5.0}}},
    }
    return yaml.safe_dump(
        {
            "rosmc_library": 1,
            "name": f"bench_{agents}",
            "models": {"robot": {"skills": skills}},
            "agents": {agent_name(i): {"kind": "dynamic", "model": "robot"} for i in range(agents)},
        },
        sort_keys=False,
    )


def mission_yaml(agents: int, skills: int) -> str:
    """A mission document: ``skills`` blueprint skills per agent and one task marker."""
    kinds = ["move", "inspect", "wait"]
    params = {
        "move": {
            "target": {"x": 1.0, "y": 2.0, "z": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0.5},
            "speed": 0.8,
        },
        "inspect": {"radius": 3.0, "mode": "quick", "tries": 2},
        "wait": {"seconds": 5.0},
    }
    tasks = {}
    for a in range(agents):
        name = agent_name(a)
        tasks[name] = [
            {
                "id": f"{name}-s{k:05d}",
                "skill": kinds[k % 3],
                "label": f"step {k}",
                "params": params[kinds[k % 3]],
                "status": "IDLE",
            }
            for k in range(skills)
        ]
    marker = {"name": "Site", "type": "POSE", "pose": {"x": 3.0, "y": 4.0}}
    return yaml.safe_dump(
        {
            "rosmc_mission": 1,
            "library": f"bench_{agents}",
            "revision": 0,
            "tasks": tasks,
            "barriers": [],
            "markers": [marker],
        },
        sort_keys=False,
    )


# -- measuring -------------------------------------------------------------------------------------
def percentiles(samples: list[float]) -> dict[str, float]:
    ordered = sorted(samples)
    p95 = ordered[min(len(ordered) - 1, round(0.95 * (len(ordered) - 1)))]
    return {
        "p50_ms": round(statistics.median(ordered) * 1000, 3),
        "p95_ms": round(p95 * 1000, 3),
        "n": len(ordered),
    }


def serialized_size(msg: Any) -> int:
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return len(buffer.getvalue())


class Bench:
    """Times operations against one running server."""

    def __init__(self, agents: int, skills: int, samples: int, seed: int = 1) -> None:
        import rosmc.msg as wire
        import rosmc.srv as srv
        import rospy

        from rosmc_server import interface

        self.wire, self.rospy = wire, rospy
        self.agents = [agent_name(i) for i in range(agents)]
        self.skills = skills
        self.samples = samples
        self.rng = random.Random(seed)
        self.proxies: dict[str, Any] = {}
        for operation, type_name in interface.SERVICES.items():
            rospy.wait_for_service(interface.service_name(operation), 30)
            self.proxies[operation] = rospy.ServiceProxy(
                interface.service_name(operation), getattr(srv, type_name), persistent=True
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
        response = self.proxies[operation](**fields)
        if getattr(response, "error_code", 0):
            raise RuntimeError(f"{operation} failed: {response.error}")
        if hasattr(response, "revision") and response.revision != self.rev:
            self.rev = response.revision
            self.changes += 1
        return response

    def timed(self, operation: str, **fields: Any) -> tuple[float, Any]:
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

    def close(self) -> None:
        self.subscriber.unregister()
        for proxy in self.proxies.values():
            proxy.close()

    def run(self) -> dict[str, dict[str, float]]:
        wire, n = self.wire, self.samples
        pv = wire.ParameterValue
        times: dict[str, list[float]] = {}
        added: list[str] = []

        def record(name: str, elapsed: float) -> None:
            times.setdefault(name, []).append(elapsed)

        for _ in range(n):  # add: append to a random agent
            agent = self.rng.choice(self.agents)
            elapsed, response = self.timed(
                "add_skill",
                base_revision=self.rev,
                agent=agent,
                skill="inspect",
                index=-1,
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=4.0)],
            )
            record("add", elapsed)
            added.append(response.skill_id)
        for number in range(n):  # edit: a parameter and the label of a loaded skill
            agent = self.rng.choice(self.agents)
            skill_id = f"{agent}-s{self.rng.randrange(1, self.skills, 3):05d}"  # an inspect
            elapsed, _ = self.timed(
                "edit_skill",
                base_revision=self.rev,
                skill_id=skill_id,
                label=f"edited {number}",
                parameters=[pv(name="radius", type=pv.FLOAT, float_value=1.0 + number % 9)],
            )
            record("edit", elapsed)
        for skill_id in added:  # delete: what the adds added
            elapsed, _ = self.timed("delete_skills", base_revision=self.rev, skill_ids=[skill_id])
            record("delete", elapsed)
        for _ in range(max(20, n // 5)):  # reorder: a whole blueprint, rotated by one
            agent = self.rng.choice(self.agents)
            task = next(
                t for t in self.call("get_mission").mission.tasks if t.agent == agent
            ).skills
            ids = [s.id for s in task if s.transfer == 0 and s.status.value == 0]
            elapsed, _ = self.timed(
                "reorder_skills", base_revision=self.rev, agent=agent, order=ids[1:] + ids[:1]
            )
            record("reorder", elapsed)
        for _ in range(max(20, n // 5)):  # add barrier: two fresh skills on two agents
            pair = self.rng.sample(self.agents, 2)
            members = [
                self.call(
                    "add_skill", base_revision=self.rev, agent=a, skill="wait", index=-1
                ).skill_id
                for a in pair
            ]
            elapsed, _ = self.timed("add_barrier", base_revision=self.rev, skill_ids=members)
            record("add_barrier", elapsed)
        bound = self.call(
            "add_skill",
            base_revision=self.rev,
            agent=self.agents[0],
            skill="move",
            index=-1,
            parameters=[pv(name="target", type=pv.POSE, marker="Site")],
        )
        del bound
        for number in range(n):  # marker move: one skill bound to it follows
            pose = wire.Pose6D(x=number % 50, y=-(number % 7), yaw=0.1)
            elapsed, _ = self.timed(
                "move_task_marker", base_revision=self.rev, name="Site", pose=pose
            )
            record("marker_move", elapsed)
        for number in range(max(20, n // 5)):  # synchronize: the first blueprint skill
            agent = self.agents[number % len(self.agents)]
            task = next(t for t in self.call("get_mission").mission.tasks if t.agent == agent)
            upto = next(s.id for s in task.skills if s.transfer == 0 and s.status.value == 0)
            elapsed, _ = self.timed(
                "synchronize", base_revision=self.rev, agent=agent, upto_id=upto
            )
            record("sync", elapsed)
        for _ in range(max(10, n // 10)):
            elapsed, _ = self.timed("get_mission")
            record("get_mission", elapsed)
        return {name: percentiles(values) for name, values in times.items()}

    def event_bytes(self) -> dict[str, int]:
        kinds = {
            self.wire.MissionEvent.SKILL_ADDED: "add",
            self.wire.MissionEvent.SKILL_EDITED: "edit",
            self.wire.MissionEvent.SKILL_DELETED: "delete",
            self.wire.MissionEvent.SKILLS_REORDERED: "reorder",
            self.wire.MissionEvent.BARRIER_ADDED: "add_barrier",
            self.wire.MissionEvent.MARKER_MOVED: "marker_move",
            self.wire.MissionEvent.SYNC_REQUESTED: "sync",
        }
        sizes: dict[str, list[int]] = {}
        with self._lock:
            events = list(self.events)
        for event in events:
            if event.kind in kinds:
                sizes.setdefault(kinds[event.kind], []).append(serialized_size(event))
        return {name: int(statistics.median(values)) for name, values in sizes.items()}


def timings(samples: list[float]) -> dict[str, float]:
    """Median and max of a few timings, in milliseconds."""
    return {
        "median_ms": round(statistics.median(samples) * 1000, 1),
        "max_ms": round(max(samples) * 1000, 1),
        "n": len(samples),
    }


def raw_get_mission_proxy() -> Any:
    """A persistent GetMission proxy that keeps the answer's bytes instead of decoding them.

    Times the server and the transport alone: decoding 10,000 skills into genpy messages is
    the client's own cost (timed apart as ``get_mission_client_decode``).
    """
    import rosmc.srv as srv
    import rospy

    from rosmc_server import interface

    class RawResponse(srv.GetMissionResponse):  # type: ignore[misc]
        def deserialize(self, data: bytes) -> Any:
            self.raw = data
            return self

    class RawGetMission:
        _type = srv.GetMission._type
        _md5sum = srv.GetMission._md5sum
        _request_class = srv.GetMissionRequest
        _response_class = RawResponse

    return rospy.ServiceProxy(interface.service_name("get_mission"), RawGetMission, persistent=True)


class WholeMission:
    """Times the operations that cost the whole mission: get, save and load."""

    def __init__(self, bench: Bench, server: Server, work: Path, repeats: int) -> None:
        self.bench = bench
        self.server = server
        self.work = work
        self.repeats = repeats
        self.number = 0
        self.raw = raw_get_mission_proxy()
        self.can_skip_document = (
            "return_document" in bench.proxies["save_mission"].request_class.__slots__
        )

    def change(self) -> None:
        """One small change (a label edit), so the next call meets a new revision."""
        self.number += 1
        pv = self.bench.wire.ParameterValue
        agent = self.bench.agents[self.number % len(self.bench.agents)]
        self.bench.call(
            "edit_skill",
            base_revision=self.bench.rev,
            skill_id=f"{agent}-s{1 + 3 * (self.number % max(1, self.bench.skills // 3)):05d}",
            label=f"whole {self.number}",
            parameters=[pv(name="radius", type=pv.FLOAT, float_value=2.5)],
        )

    def run(self) -> dict[str, Any]:
        times: dict[str, list[float]] = {}

        def timed(name: str, operation: str, **fields: Any) -> Any:
            elapsed, response = self.bench.timed(operation, **fields)
            times.setdefault(name, []).append(elapsed)
            return response

        def raw_get(name: str) -> bytes:
            started = time.perf_counter()
            response = self.raw.call(self.raw.request_class())
            times.setdefault(name, []).append(time.perf_counter() - started)
            return bytes(response.raw)

        import rosmc.srv as srv

        path = str(self.work / "missions" / "bench.yaml")
        document = ""
        for _ in range(self.repeats):
            self.change()
            timed("get_mission_after_change", "get_mission")
            timed("get_mission_same_revision", "get_mission")
            self.change()
            raw_get("get_mission_wire_after_change")
            data = raw_get("get_mission_wire_same_revision")
            started = time.perf_counter()
            srv.GetMissionResponse().deserialize(data)
            times.setdefault("get_mission_client_decode", []).append(time.perf_counter() - started)
            self.change()
            fields = {"return_document": False} if self.can_skip_document else {}
            saved = timed("save_to_path", "save_mission", path=path, **fields)
            self.change()
            document = timed("save_returning_document", "save_mission").document
        sizes = {"document_bytes": len(document.encode()), "path_reply_bytes": len(saved.document)}
        peaks = {"server_peak_rss_after_get_and_save_mib": self.server.peak_rss_mib()}
        for _ in range(self.repeats):
            cpu = self.server.cpu_seconds()
            timed(
                "load_saved_document",
                "load_mission",
                base_revision=self.bench.rev,
                document=document,
            )
            times.setdefault("load_saved_document_server_cpu", []).append(
                self.server.cpu_seconds() - cpu
            )
        self.raw.close()
        peaks["server_peak_rss_after_loads_mib"] = self.server.peak_rss_mib()
        # A server that does not log its load phases (an older one) gives none.
        phases = self.server.load_phases()[-self.repeats :]
        names = ("read_and_check", "serialize", "apply_and_journal")
        split = {
            f"load_server_{name}_ms": round(statistics.median(values), 1)
            for name, values in zip(names, zip(*phases, strict=True), strict=False)
        }
        return {name: timings(values) for name, values in times.items()} | sizes | peaks | split


def subscriber_cpu(bench: Bench, server: Server, seconds: float) -> dict[str, Any]:
    """The server's CPU share over ``seconds`` of 10 changes/s, without and with a subscriber."""
    import rosmc.msg as wire

    from rosmc_server import interface

    whole = WholeMission(bench, server, server.journal_dir, 1)
    received: list[int] = []

    def run() -> float:
        cpu, started = server.cpu_seconds(), time.monotonic()
        for tick in range(int(seconds * 10)):
            whole.change()
            time.sleep(max(0.0, started + (tick + 1) * 0.1 - time.monotonic()))
        return (server.cpu_seconds() - cpu) / (time.monotonic() - started)

    time.sleep(3.0)  # let the load's snapshot settle
    without = run()
    subscriber = bench.rospy.Subscriber(
        interface.MISSION_TOPIC, wire.Mission, lambda msg: received.append(msg.revision)
    )
    time.sleep(3.0)  # connected, and the latched snapshot delivered
    try:
        with_subscriber = run()
    finally:
        subscriber.unregister()
    return {
        "seconds": seconds,
        "changes_per_s": 10,
        "cpu_share_without_subscriber": round(without, 4),
        "cpu_share_with_subscriber": round(with_subscriber, 4),
        "subscriber_cost_share": round(with_subscriber - without, 4),
        "snapshots_received": len(received),
    }


def bench_size(
    env: dict[str, str],
    work: Path,
    agents: int,
    skills: int,
    samples: int,
    profile: Path | None,
    repeats: int = 5,
    cpu_seconds: float = 0.0,
) -> dict[str, Any]:
    import rosmc.msg  # noqa: F401  (fail early without the built messages)

    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(agents))
    server = Server(env, work, library, profile)
    bench = Bench(agents, skills, samples)
    try:
        document = mission_yaml(agents, skills)
        rss_started = server.rss_mib()
        started = time.perf_counter()
        bench.call("load_mission", base_revision=bench.rev, document=document)
        load_s = time.perf_counter() - started
        time.sleep(0.5)  # the snapshot of the loaded mission is built and journaled
        result: dict[str, Any] = {
            "agents": agents,
            "skills_per_agent": skills,
            "load_document_s": round(load_s, 3),
            "server_rss_before_load_mib": rss_started,
            "server_peak_rss_after_load_mib": server.peak_rss_mib(),
        }
        if repeats > 0:  # first: loading is refused once robots hold synchronized skills
            (work / "missions").mkdir(exist_ok=True)
            result["whole"] = WholeMission(bench, server, work, repeats).run()
        if samples > 0:
            journal_start, changes_start = server.journal_bytes(), bench.changes
            result["latency"] = bench.run()
            time.sleep(1.0)  # let coalesced snapshots land in the journal and events arrive
            changes = bench.changes - changes_start
            result["event_bytes"] = bench.event_bytes()
            result["journal_bytes_per_change"] = round(
                (server.journal_bytes() - journal_start) / changes
            )
            result["changes"] = changes
        if cpu_seconds > 0:
            result["snapshot_subscriber"] = subscriber_cpu(bench, server, cpu_seconds)
        snapshot = bench.call("get_mission").mission
        result["total_skills"] = sum(len(t.skills) for t in snapshot.tasks)
        result["snapshot_bytes"] = serialized_size(snapshot)
        result["server_peak_rss_mib"] = server.peak_rss_mib()
    finally:
        bench.close()
        server.stop(profiled=profile is not None)
    return result


def profile_summary(path: Path, top: int = 25) -> list[str]:
    stream = io.StringIO()
    stats = pstats.Stats(str(path), stream=stream)
    stats.sort_stats("tottime").print_stats(top)
    return [line for line in stream.getvalue().splitlines() if line.strip()][-top:]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="2x10,5x100,20x500", help="AGENTSxSKILLS,...")
    parser.add_argument("--samples", type=int, default=300, help="samples per operation")
    parser.add_argument("--profile", action="store_true", help="cProfile the largest size")
    parser.add_argument(
        "--whole-repeats", type=int, default=5, help="times each whole-mission path (0: skip)"
    )
    parser.add_argument(
        "--cpu-seconds",
        type=float,
        default=0.0,
        help="at the largest size, server CPU over this many s of 10 changes/s, "
        "without and with a /rosmc/mission subscriber",
    )
    args = parser.parse_args(argv)
    sizes = [tuple(int(x) for x in size.split("x")) for size in args.sizes.split(",")]
    largest = max(sizes, key=lambda size: size[0] * size[1])
    with tempfile.TemporaryDirectory(prefix="bench_server_") as tmp:
        base = Path(tmp)
        (base / "log").mkdir()
        with ros_master(base) as env:
            import rospy

            rospy.init_node("bench_server", anonymous=True, disable_signals=True)
            results = [
                bench_size(
                    env,
                    base / f"{a}x{s}",
                    a,
                    s,
                    args.samples,
                    None,
                    args.whole_repeats,
                    args.cpu_seconds if (a, s) == largest else 0.0,
                )
                for a, s in sizes
            ]
            output: dict[str, Any] = {"target_at_20x500": TARGET, "sizes": results}
            if args.profile:
                a, s = largest
                stats = base / "server.prof"
                bench_size(env, base / "profiled", a, s, args.samples, stats, args.whole_repeats)
                output["profile_top_tottime"] = profile_summary(stats)
            rospy.signal_shutdown("done")
    print(json.dumps(output, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
