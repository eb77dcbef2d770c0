"""Benchmark of the rviz marker node: what rviz receives per mission event; prints one JSON object.

Starts its own ``rosmaster``, a ``mission_server`` on a library of 20 robots (the Mars team's
models) and the marker node (``scripts/markers_node``). In this process, 20 robots move as
the simulator moves them: TF ``map -> <robot>/base_link`` and ``/<robot>/telemetry`` at
10 Hz (pose, battery and Wi-Fi change in every message); ``robot_00``'s link end is played
here (uploads acknowledged, status reports sent). The mission gets 200 task markers, half of
them bound to blueprint skills
(``robot_00`` has one per round). Then, subscribed to ``/rosmc/markers/update`` as rviz is:

* ``idle``: 5 s without mission events: what the robots' motion alone costs per second
  (updates, interactive markers inserted, pose updates, status-icon markers);
* ``per_event``: one event at a time, per kind (``add``, ``edit`` (rebinds to another
  marker), ``delete``, ``marker_move``, ``sync``, ``status`` (a robot report)): from just
  before the call to 0.3 s after the first update that carries a marker the event changes,
  the updates, interactive markers (full inserts), pose updates and erases rviz received,
  and the latency from the arrival here of the ``/rosmc/mission_events`` message to the
  arrival of that update (p50/p95/max);
* ``sustained``: ``--burst`` marker moves back to back: events per second the node keeps up
  with and the latency under that load;
* the load average before and after.

Run from the repository root::

    source env.sh
    python bench/bench_markers.py [--samples 30] [--burst 200]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from _marker_watch import FakeRobot, UpdateWatch, team_motion
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


SETTLE = 0.3  # s after the event's update in which its other updates still count
TASK = "task/"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=30, help="events per kind")
    parser.add_argument("--burst", type=int, default=200)
    args = parser.parse_args()
    load_before = os.getloadavg()[0]
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
                figures = run(args, work)
            except Exception:
                for name in ("server.log", "markers.log"):  # what went wrong, said there
                    text = (work / name).read_text(errors="replace")
                    print(f"--- {name}\n{text[-3000:]}", file=sys.stderr)
                raise
            finally:
                stop_process(node)
                server.stop()
    figures["load_average"] = {"before": round(load_before, 2), "after": os.getloadavg()[0]}
    print(json.dumps(figures, indent=2))
    return 0


class Events:
    """Mission events made one at a time, each with what rviz received for it."""

    def __init__(self, watch: UpdateWatch, client: Any) -> None:
        self.watch = watch
        self.client = client
        self.by_kind: dict[str, list[dict[str, float]]] = {}

    def measure(self, kind: str, names: set[str], call: Callable[[], int]) -> None:
        """Run ``call`` (returns the event's revision); keep what ``names``' update cost."""
        began = time.monotonic()
        revision = call()
        arrived = self.watch.event_time(revision)
        expected = {TASK + n for n in names}
        first = self.watch.first_carrying(expected, began)
        time.sleep(max(0.0, first + SETTLE - time.monotonic()))
        updates = self.watch.between(began, first + SETTLE)
        arrays, icons = self.watch.icon_markers_between(began, first + SETTLE)
        self.by_kind.setdefault(kind, []).append(
            {
                "latency": max(0.0, first - arrived),
                "updates": len(updates),
                "markers": sum(len(u.markers) for u in updates),
                "poses": sum(len(u.poses) for u in updates),
                "erases": sum(len(u.erases) for u in updates),
                "icon_markers": icons,
                "icon_arrays": arrays,
            }
        )

    def figures(self) -> dict[str, Any]:
        """Per kind: the means of the counts, their max, and the latency."""
        out: dict[str, Any] = {}
        for kind, samples in self.by_kind.items():
            figure: dict[str, Any] = {"n": len(samples)}
            for key in ("updates", "markers", "poses", "erases", "icon_markers"):
                values = [s[key] for s in samples]
                figure[f"{key}_mean"] = round(statistics.mean(values), 2)
                figure[f"{key}_max"] = max(values)
            figure["latency"] = summary([s["latency"] for s in samples])
            out[kind] = figure
        return out


def idle(watch: UpdateWatch, seconds: float = 5.0) -> dict[str, float]:
    """What the robots' motion alone costs per second."""
    began = time.monotonic()
    time.sleep(seconds)
    updates = watch.between(began, began + seconds)
    arrays, icons = watch.icon_markers_between(began, began + seconds)
    return {
        "updates_per_s": round(len(updates) / seconds, 2),
        "markers_per_s": round(sum(len(u.markers) for u in updates) / seconds, 2),
        "poses_per_s": round(sum(len(u.poses) for u in updates) / seconds, 2),
        "icon_arrays_per_s": round(arrays / seconds, 2),
        "icon_markers_per_s": round(icons / seconds, 2),
    }


def run(args: argparse.Namespace, work: Path) -> dict[str, Any]:
    import rospy

    from rosmc_server.core import MarkerType, Pose, TaskMarker
    from rosmc_server.ros.client import MissionClient

    rospy.init_node("bench_markers", anonymous=True, disable_signals=True)
    deadline = time.monotonic() + 60
    while "markers for library" not in (work / "markers.log").read_text(errors="replace"):
        if time.monotonic() > deadline:
            raise RuntimeError("the marker node did not start")
        time.sleep(0.05)
    robots = [f"robot_{i:02d}" for i in range(ROBOTS)]
    robot = FakeRobot(robots[0])
    client = MissionClient(10.0)
    client.get_mission()
    names = []
    blueprint: list[tuple[str, str]] = []  # robots[0]'s blueprint: (skill, its marker)
    for i in range(MARKERS):
        name = client.add_task_marker(
            TaskMarker(f"m{i:03d}", MarkerType.POSE, Pose(i % 20, i // 20))
        ).name
        names.append(name)
        if i % 2 == 0:
            # robots[0] gets one skill per round to synchronize and run, the others the rest
            half = i // 2
            agent = robots[0] if half < args.samples else robots[1 + half % (ROBOTS - 1)]
            added = client.add_skill(agent, "navigate_to", bindings={"target": name})
            if agent == robots[0]:
                blueprint.append((added.skill_id, name))
    free = [n for i, n in enumerate(names) if i % 2 == 1]  # bound to nothing
    bound = [n for i, n in enumerate(names) if i % 2 == 0]
    watch = UpdateWatch()
    watch.start()
    stop = threading.Event()
    motion = threading.Thread(target=team_motion, args=(robots, stop), daemon=True)
    motion.start()
    deadline = time.monotonic() + 30
    while not robot.connected():
        if time.monotonic() > deadline:
            raise RuntimeError("the server does not hear robot_00's link")
        time.sleep(0.05)
    robot.hello()
    time.sleep(3.0)  # telemetry and TF flowing, subscriptions connected
    figures: dict[str, Any] = {
        "robots": ROBOTS,
        "task_markers": MARKERS,
        "telemetry_and_tf_hz_per_robot": 10,
        "idle": idle(watch),
    }
    events = Events(watch, client)
    for k in range(args.samples):
        one_round(events, robot, robots, k, free, bound, blueprint)
    figures["per_event"] = events.figures()
    figures["sustained"] = sustained(watch, client, bound, args.burst)
    stop.set()
    motion.join()
    return figures


def one_round(
    events: Events,
    robot: FakeRobot,
    robots: list[str],
    k: int,
    free: list[str],
    bound: list[str],
    blueprint: list[tuple[str, str]],
) -> None:
    """One event of each kind: add, edit, delete and move elsewhere; sync and status on
    ``robot`` (robots[0], whose link end this process plays, its ``blueprint`` in order)."""
    from rosmc_server.core import Pose, SkillStatus

    client = events.client
    agent = robots[1 + k % (len(robots) - 1)]
    first, second = free[(2 * k) % len(free)], free[(2 * k + 1) % len(free)]
    added: list[str] = []

    def add() -> int:
        result = client.add_skill(agent, "navigate_to", bindings={"target": first})
        added.append(result.skill_id)
        return int(result.revision)

    events.measure("add", {first}, add)
    events.measure(
        "edit",
        {first, second},
        lambda: client.edit_skill(added[-1], bindings={"target": second}).revision,
    )
    events.measure("delete", {second}, lambda: client.delete_skills([added[-1]]).revision)
    moved = bound[(k * 7) % len(bound)]
    pose = Pose(k % 20 + 0.5, k // 20 % 10, yaw=0.1 * k)
    events.measure("marker_move", {moved}, lambda: client.move_task_marker(moved, pose).revision)
    # robots[0]: the head of its blueprint synchronized and run to the end
    skill, target = blueprint.pop(0)
    events.measure("sync", {target}, lambda: client.synchronize(robots[0], skill).revision)
    events.measure("status", {target}, lambda: report(robot, skill, int(SkillStatus.RUNNING)))
    events.measure("status", {target}, lambda: report(robot, skill, int(SkillStatus.SUCCESS)))


def report(robot: FakeRobot, skill: str, status: int) -> int:
    """Report ``status`` of ``skill``; the revision of the event it makes."""
    from rosmc_server.ros.client import MissionClient

    client = MissionClient(10.0)
    before = client.get_mission().revision
    robot.report(skill, status)
    deadline = time.monotonic() + 10
    resend = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        time.sleep(0.01)
        if time.monotonic() > resend:
            robot.resend()
            resend += 1.0
        mission = client.get_mission()
        if mission.revision > before and mission.skill(skill).status.value == status:
            return mission.revision
    raise RuntimeError(
        f"the server did not take report {status} of {skill} "
        f"(it has {mission.skill(skill).status}, the robot holds {robot.queue})"
    )


def sustained(watch: UpdateWatch, client: Any, bound: list[str], burst: int) -> dict[str, Any]:
    """Moves back to back: how fast the node keeps up, and the latency meanwhile."""
    from rosmc_server.core import Pose

    began = time.monotonic()
    sent: list[tuple[str, int, float]] = []
    for k in range(burst):
        name = bound[(k * 7) % len(bound)]
        result = client.move_task_marker(name, Pose(k % 20 + 0.25, (k // 20) % 10, yaw=0.2 * k))
        sent.append((name, result.revision, time.monotonic()))
    end = time.monotonic()
    latencies, last = [], began
    for name, revision, at in sent:
        arrived = watch.event_time(revision, timeout=30.0)
        update = watch.first_carrying({TASK + name}, at - 0.001, timeout=30.0)
        latencies.append(max(0.0, update - arrived))
        last = max(last, update)
    return {
        "moves": burst,
        "send_seconds": round(end - began, 3),
        "events_per_second": round(burst / (last - began), 1),
        "lag_after_last_event_ms": round((last - end) * 1000, 1),
        "latency_under_load": summary(latencies),
    }


if __name__ == "__main__":
    sys.exit(main())
