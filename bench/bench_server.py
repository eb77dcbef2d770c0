"""Benchmark of the mission server's operator services; prints one JSON object.

Starts its own ``rosmaster`` on a free loopback port and, per mission size (agents x
skills per agent), a real ``mission_server`` on a generated library of that many dynamic
agents. The mission is loaded as one document, then each operation is timed from a
client with persistent service proxies: median and p95 latency of add, edit, delete,
reorder, add barrier, marker move, synchronize and get_mission; bytes per event, per
snapshot and per journaled change; the server's peak RSS. Run from the repository root::

    source env.sh
    python bench/bench_server.py [--sizes 2x10,5x100,20x500] [--samples 300] [--profile]

``--profile`` runs the largest size a second time under cProfile (every server thread)
and adds the top functions by internal time to the output.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import pstats
import random
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

    def peak_rss_mib(self) -> float:
        for line in Path(f"/proc/{self.process.pid}/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return round(int(line.split()[1]) / 1024, 1)
        return -1.0

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


def bench_size(
    env: dict[str, str], work: Path, agents: int, skills: int, samples: int, profile: Path | None
) -> dict[str, Any]:
    import rosmc.msg  # noqa: F401  (fail early without the built messages)

    work.mkdir(parents=True, exist_ok=True)
    library = work / "library.yaml"
    library.write_text(library_yaml(agents))
    server = Server(env, work, library, profile)
    bench = Bench(agents, skills, samples)
    try:
        document = mission_yaml(agents, skills)
        started = time.perf_counter()
        bench.call("load_mission", base_revision=bench.rev, document=document)
        load_s = time.perf_counter() - started
        time.sleep(0.5)  # the snapshot of the loaded mission is built and journaled
        journal_start, changes_start = server.journal_bytes(), bench.changes
        latencies = bench.run()
        time.sleep(1.0)  # let coalesced snapshots land in the journal and events arrive
        changes = bench.changes - changes_start
        snapshot = bench.call("get_mission").mission
        result = {
            "agents": agents,
            "skills_per_agent": skills,
            "total_skills": sum(len(t.skills) for t in snapshot.tasks),
            "load_document_s": round(load_s, 3),
            "latency": latencies,
            "event_bytes": bench.event_bytes(),
            "snapshot_bytes": serialized_size(snapshot),
            "journal_bytes_per_change": round((server.journal_bytes() - journal_start) / changes),
            "changes": changes,
            "server_peak_rss_mib": server.peak_rss_mib(),
        }
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
    args = parser.parse_args(argv)
    sizes = [tuple(int(x) for x in size.split("x")) for size in args.sizes.split(",")]
    with tempfile.TemporaryDirectory(prefix="bench_server_") as tmp:
        base = Path(tmp)
        (base / "log").mkdir()
        with ros_master(base) as env:
            import rospy

            rospy.init_node("bench_server", anonymous=True, disable_signals=True)
            results = [
                bench_size(env, base / f"{a}x{s}", a, s, args.samples, None) for a, s in sizes
            ]
            output: dict[str, Any] = {"target_at_20x500": TARGET, "sizes": results}
            if args.profile:
                a, s = max(sizes, key=lambda size: size[0] * size[1])
                stats = base / "server.prof"
                bench_size(env, base / "profiled", a, s, args.samples, stats)
                output["profile_top_tottime"] = profile_summary(stats)
            rospy.signal_shutdown("done")
    print(json.dumps(output, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
