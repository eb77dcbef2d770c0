"""Benchmark of the rviz marker node; prints one JSON object.

Starts its own ``rosmaster``, a ``mission_server`` on a library of 20 robots (the Mars team's
models), the marker node (``scripts/markers_node``) and, in this process, 20 robots that
publish ``/<robot>/telemetry`` at 10 Hz (pose, battery, Wi-Fi changing every message).
The mission gets 200 task markers (half of them bound to blueprint skills). Then:

* latency: one ``move_task_marker`` at a time; from the moment this process receives the
  server's ``/rosmc/mission_events`` message to the moment it receives the marker node's
  ``/rosmc/markers/update`` carrying the moved marker (p50/p95/max, ms);
* sustained: moves sent back to back for ``--burst`` moves; events per second the node
  keeps up with (last update received after the last event) and the latency under load;
* incremental: the mean number of interactive markers per update message (a full rebuild
  would send all 200+ every time).

Run from the repository root::

    source env.sh
    python bench/bench_markers.py [--samples 200] [--burst 300]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _server_harness import REPO, Server, ros_master, stop_process

ROBOTS = 20
MARKERS = 200
MODELS = ("drone_scout", "rover_science", "rover_manipulator")


def library_yaml() -> str:
    """The Mars team's models with 20 robots."""
    document = yaml.safe_load((REPO / "rosmc_server" / "config" / "mars_team.yaml").read_text())
    agents = {f"robot_{i:02d}": {"kind": "dynamic", "model": MODELS[i % 3]} for i in range(ROBOTS)}
    agents["lander"] = {"kind": "static", "model": "lander"}
    document["agents"] = agents
    return yaml.safe_dump(document)


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def summary(values: list[float]) -> dict[str, float]:
    ms = [v * 1000 for v in values]
    return {
        "p50_ms": round(statistics.median(ms), 2),
        "p95_ms": round(percentile(ms, 0.95), 2),
        "max_ms": round(max(ms), 2),
        "n": len(ms),
    }


class Watcher:
    """Arrival times of mission events (by revision) and of marker updates (by marker)."""

    def __init__(self) -> None:
        import rosmc.msg as wire
        import rospy
        from visualization_msgs.msg import InteractiveMarkerUpdate

        self.lock = threading.Condition()
        self.events: dict[int, float] = {}
        self.updates: dict[str, list[float]] = {}
        self.sizes: list[int] = []
        rospy.Subscriber(
            "/rosmc/mission_events", wire.MissionEvent, self._on_event, queue_size=10000
        )
        rospy.Subscriber(
            "/rosmc/markers/update", InteractiveMarkerUpdate, self._on_update, queue_size=10000
        )

    def _on_event(self, msg: Any) -> None:
        with self.lock:
            self.events[msg.revision] = time.monotonic()
            self.lock.notify_all()

    def _on_update(self, msg: Any) -> None:
        now = time.monotonic()
        names = [m.name for m in msg.markers] + [p.name for p in msg.poses]
        if not names:
            return  # keep-alive
        with self.lock:
            self.sizes.append(len(names))
            for name in names:
                self.updates.setdefault(name, []).append(now)
            self.lock.notify_all()

    def wait_update(self, name: str, count: int, timeout: float = 10.0) -> float:
        """The arrival time of the ``count``-th update of ``name``."""
        deadline = time.monotonic() + timeout
        with self.lock:
            while len(self.updates.get(name, [])) < count:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RuntimeError(f"no update {count} of {name}")
                self.lock.wait(left)
            return self.updates[name][count - 1]

    def event_time(self, revision: int, timeout: float = 10.0) -> float:
        deadline = time.monotonic() + timeout
        with self.lock:
            while revision not in self.events:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RuntimeError(f"no event {revision}")
                self.lock.wait(left)
            return self.events[revision]


def telemetry(stop: threading.Event) -> None:
    """20 robots reporting at 10 Hz."""
    import rosmc.msg as wire
    import rospy

    publishers = [
        rospy.Publisher(f"/robot_{i:02d}/telemetry", wire.Telemetry, queue_size=10)
        for i in range(ROBOTS)
    ]
    tick = 0
    while not stop.wait(0.1):
        tick += 1
        for i, pub in enumerate(publishers):
            angle = tick * 0.05 + i
            msg = wire.Telemetry(
                agent=f"robot_{i:02d}",
                stamp=rospy.Time.now(),
                frame_id="map",
                battery=0.5 + 0.4 * math.sin(angle),
                wifi_signal=-60 + 10 * math.cos(angle),
                in_coverage=True,
            )
            msg.pose.x, msg.pose.y, msg.pose.yaw = 10 * math.cos(angle), 10 * math.sin(angle), angle
            pub.publish(msg)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=200)
    parser.add_argument("--burst", type=int, default=300)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_markers_") as tmp:
        work = Path(tmp)
        (work / "home").mkdir()
        with ros_master(work / "home") as env:
            library = work / "library.yaml"
            library.write_text(library_yaml())
            server = Server(env, work, library, None)
            log = (work / "markers.log").open("wb")
            node = subprocess.Popen(
                [sys.executable, str(REPO / "scripts" / "markers_node")],
                env=env,
                cwd=REPO,
                stdout=log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
            try:
                return run(args, work)
            finally:
                stop_process(node)  # never raises: the figures are printed already
                server.stop()


def run(args: argparse.Namespace, work: Path) -> int:
    import rospy

    from rosmc_server.core import MarkerType, Pose, TaskMarker
    from rosmc_server.ros.client import MissionClient

    rospy.init_node("bench_markers", anonymous=True, disable_signals=True)
    deadline = time.monotonic() + 60
    while "markers for library" not in (work / "markers.log").read_text(errors="replace"):
        if time.monotonic() > deadline:
            raise RuntimeError("the marker node did not start")
        time.sleep(0.05)
    client = MissionClient(10.0)
    client.get_mission()
    names = []
    for i in range(MARKERS):
        name = client.add_task_marker(
            TaskMarker(f"m{i:03d}", MarkerType.POSE, Pose(i % 20, i // 20))
        ).name
        names.append(name)
        if i % 2 == 0:
            client.add_skill(f"robot_{i % ROBOTS:02d}", "navigate_to", bindings={"target": name})
    watcher = Watcher()
    stop = threading.Event()
    reporter = threading.Thread(target=telemetry, args=(stop,), daemon=True)
    reporter.start()
    time.sleep(2.0)  # telemetry flowing, subscriptions connected
    latencies: list[float] = []
    seen: dict[str, int] = {}
    for k in range(args.samples):
        name = names[k % MARKERS]
        before = len(watcher.updates.get(f"task/{name}", []))
        result = client.move_task_marker(name, Pose(k % 20 + 0.5, k // 20 % 10, yaw=0.1 * k))
        arrived = watcher.wait_update(f"task/{name}", before + 1)
        latencies.append(arrived - watcher.event_time(result.revision))
        seen[name] = before + 1
    # sustained: back to back
    sizes_before = len(watcher.sizes)
    started = time.monotonic()
    last: tuple[str, int] | None = None
    burst: list[tuple[str, int, int]] = []
    for k in range(args.burst):
        name = names[(k * 7) % MARKERS]
        before = len(watcher.updates.get(f"task/{name}", []))
        result = client.move_task_marker(name, Pose(k % 20 + 0.25, (k // 20) % 10, yaw=0.2 * k))
        burst.append((name, result.revision, before))
        last = (name, before)
    assert last is not None
    end = time.monotonic()
    for name, _, before in burst:  # every moved marker's update must arrive
        watcher.wait_update(f"task/{name}", before + 1, timeout=30.0)
    finished = max(watcher.updates[f"task/{n}"][-1] for n, _, _ in burst)
    under_load = []
    for name, revision, before in burst:
        times = watcher.updates[f"task/{name}"]
        if len(times) > before:
            under_load.append(times[before] - watcher.event_time(revision))
    stop.set()
    reporter.join()
    sizes = watcher.sizes[:sizes_before]
    result = {
        "robots": ROBOTS,
        "task_markers": MARKERS,
        "telemetry_hz_per_robot": 10,
        "event_to_marker_update": summary(latencies),
        "sustained": {
            "moves": args.burst,
            "send_seconds": round(end - started, 3),
            "events_per_second": round(args.burst / (finished - started), 1),
            "lag_after_last_event_ms": round((finished - end) * 1000, 1),
            "latency_under_load": summary(under_load),
        },
        "markers_per_update_mean": round(statistics.mean(sizes), 2) if sizes else None,
        "target_p95_ms": 50,
    }
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
