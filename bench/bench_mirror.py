"""Benchmark of the client's mission mirror; prints one JSON object.

Two figures at 20 robots x 500 skills (``--agents``, ``--skills``):

* ``apply``: the mirror's own cost per event (pure Python, no ROS): a stream of typical
  events from a real :class:`Mission` — parameter edits, robot status reports, adds and
  deletes, marker moves, reorders — applied to a :class:`MissionMirror` with one listener;
  p50/p95 per event. Target: ≤ 1 ms.
* ``follow``: a real ``rosmaster`` and ``mission_server`` holding the mission, a
  :class:`MissionFollower` in this process, and edits made through the operator services:
  the time from the service's answer to the mirror's callback with that revision, and from
  the request to the callback; the time to the first snapshot. Target: callbacks within
  5 ms of the publish.

Run from the repository root::

    source env.sh
    python bench/bench_mirror.py [--agents 20] [--skills 500] [--samples 300]
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

from bench_server import (  # noqa: E402  (bench/ is not a package)
    Server,
    agent_name,
    library_yaml,
    mission_yaml,
    percentiles,
    ros_master,
)

from rosmc_server.core import (  # noqa: E402
    MarkerType,
    Mission,
    MissionState,
    Pose,
    SkillStatus,
    TaskMarker,
)
from rosmc_server.core.files.persistence import parse_mission  # noqa: E402
from rosmc_server.core.live.mirror import MissionMirror  # noqa: E402
from rosmc_server.core.live.updates import MirrorUpdate  # noqa: E402
from rosmc_server.core.skills.library import library_from_dict  # noqa: E402

TARGET = {"apply_p95_ms": 1.0, "callback_after_reply_p95_ms": 5.0}


def bench_apply(agents: int, skills: int, samples: int) -> dict[str, Any]:
    """The mirror's cost per event, fed from a real mission of ``agents`` x ``skills``."""
    import yaml

    library = library_from_dict(yaml.safe_load(library_yaml(agents)), "bench")
    content, _ = parse_mission(mission_yaml(agents, skills), library, "bench")
    counter = itertools.count()
    mission = Mission(library, content, 0, new_id=lambda p: f"{p}-n{next(counter)}")
    mission.add_marker(TaskMarker("Spot", MarkerType.POSE, Pose(1, 1)))
    mirror = MissionMirror()
    seen: list[int] = []
    mirror.subscribe(lambda update: seen.append(update.revision))
    mirror.on_snapshot(MissionState(mission.state.content(), mission.revision))
    for a in range(agents):  # robots at work: a synchronized head on every robot
        agent = agent_name(a)
        head = mission.state.task(agent)[0].id
        mirror.on_event(mission.synchronize(agent, head))
        mirror.on_event(mission.confirm_synchronized(agent, [head]))
    times: dict[str, list[float]] = {}
    for n in range(samples):
        agent = agent_name(n % agents)
        task = mission.state.task(agent)
        sections = mission.state.sections(agent)
        blueprint = [s.id for s in task[sections.editable_start :]]
        kind, event = _next_event(mission, n, agent, task, blueprint)
        start = time.perf_counter()
        mirror.on_event(event)
        times.setdefault(kind, []).append(time.perf_counter() - start)
    assert mirror.state is not None and mirror.state.content() == mission.state.content()
    everything = [t for series in times.values() for t in series]
    return {
        "per_event": percentiles(everything),
        "by_kind": {kind: percentiles(series) for kind, series in times.items()},
        "events": len(seen),
    }


def _next_event(mission: Mission, n: int, agent: str, task: Any, blueprint: list[str]) -> Any:
    step = n % 6
    if step == 0:
        return "edit", mission.edit_skill(blueprint[n % 50], label=f"edited {n}")
    if step == 1:
        head = task[0]
        status = SkillStatus.RUNNING if head.status is SkillStatus.IDLE_SYNCHRONIZED else None
        if status is not None:
            return "status", mission.report_status(head.id, status)
        return "status", mission.report_status(
            head.id,
            SkillStatus.PAUSED if head.status is SkillStatus.RUNNING else SkillStatus.RUNNING,
        )
    if step == 2:
        return "add", mission.add_skill(agent, "wait", {"seconds": 2.0})
    if step == 3:
        return "delete", mission.delete_skills([blueprint[-1]])
    if step == 4:
        return "marker_move", mission.move_marker("Spot", Pose(n % 7, n % 5))
    order = blueprint[:]
    order[0], order[1] = order[1], order[0]
    return "reorder", mission.reorder(agent, order)


def bench_follow(agents: int, skills: int, samples: int) -> dict[str, Any]:
    """Server change to mirror callback, through a real master and server."""
    with tempfile.TemporaryDirectory(prefix="bench_mirror_") as tmp:
        work = Path(tmp)
        library = work / "library.yaml"
        library.write_text(library_yaml(agents))
        with ros_master(work) as env:
            server = Server(env, work, library, None)
            try:
                return _measure_follow(agents, skills, samples, work)
            finally:
                server.stop()


def _measure_follow(agents: int, skills: int, samples: int, work: Path) -> dict[str, Any]:
    import rospy

    from rosmc_server.ros.client import MissionClient, MissionFollower

    rospy.init_node("bench_mirror", anonymous=True, disable_signals=True)
    client = MissionClient(timeout=30.0)
    client.load_mission(document=mission_yaml(agents, skills))
    arrived: dict[int, float] = {}
    condition = threading.Condition()

    def on_update(update: MirrorUpdate) -> None:
        with condition:
            arrived[update.revision] = time.perf_counter()
            condition.notify_all()

    opened = time.perf_counter()
    follower = MissionFollower(timeout=30.0)
    follower.mirror.subscribe(on_update)
    follower.start()
    with condition:
        condition.wait_for(lambda: follower.mirror.state is not None, 60)
    first_snapshot = time.perf_counter() - opened
    ids = [s.id for s in client.fetch_mission().task(agent_name(0))]
    after_reply: list[float] = []
    after_request: list[float] = []
    for n in range(samples):
        sent = time.perf_counter()
        revision = client.edit_skill(ids[n % len(ids)], label=f"edit {n}").revision
        replied = time.perf_counter()
        with condition:
            if not condition.wait_for(lambda rev=revision: rev in arrived, 10):
                raise RuntimeError(f"no mirror callback for revision {revision}")
            at = arrived[revision]
        after_reply.append(max(0.0, at - replied))
        after_request.append(at - sent)
    follower.close()
    client.close()
    return {
        "first_snapshot_s": round(first_snapshot, 3),
        "callback_after_reply": percentiles(after_reply),
        "callback_after_request": percentiles(after_request),
        "snapshots_requested": follower.mirror.snapshots_requested,
    }


def main(argv: list[str] | None = None) -> int:
    """Run both parts and print the JSON figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", type=int, default=20)
    parser.add_argument("--skills", type=int, default=500)
    parser.add_argument("--samples", type=int, default=300)
    args = parser.parse_args(argv)
    result = {
        "mission": f"{args.agents}x{args.skills}",
        "target": TARGET,
        "apply": bench_apply(args.agents, args.skills, args.samples * 4),
        "follow": bench_follow(args.agents, args.skills, args.samples),
    }
    print(json.dumps(result, indent=2), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
