"""Benchmark of the mission executors behind a real mission server; prints one JSON object.

Starts its own ``rosmaster`` on a free port (private ``ROS_HOME``), a mission server
with a generated 20-robot library and one executor process per robot, and measures:

* ``sync_to_start``: from the operator's Synchronize call returning to the skill
  RUNNING on a started, idle robot (the robot's own RUNNING stamp), and to the
  operator seeing it on ``/rosmc/mission_events``;
* ``barrier_skew``: max - min of the members' RUNNING ``started`` stamps (the
  robots' clocks, one host here), per barrier of 2, 5 and 20 robots that arrive
  at different times;
* ``report_delivery_after_outage``: robots behind the link emulator finish their
  skills during a blackout; time from the end of the blackout to the server
  showing every skill SUCCESS.

Run from the repository root after ``source env.sh``::

    python bench/bench_executor.py [--samples N] [--rounds N] [--robots 2,5,20]

Every robot is a Python process: on a 2-core machine the 20-robot figures include
CPU contention between 20 executors, the server and the benchmark itself.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import rosmc.srv as srv
import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

from _server_harness import ros_master  # noqa: E402

from rosmc_server.core import SkillStatus  # noqa: E402
from tests.integration.executor_fixtures import (  # noqa: E402
    TEST_LIBRARY,
    Operator,
    RosmcSystem,
    running_stamps,
)

S = SkillStatus


def team_library(directory: Path, robots: int) -> Path:
    """The test team's library with ``robots`` dynamic agents a01, a02, ..."""
    data = yaml.safe_load(TEST_LIBRARY.read_text())
    data["name"] = f"bench_team_{robots}"
    data["agents"] = {
        f"a{i:02d}": {"kind": "dynamic", "model": "tester"} for i in range(1, robots + 1)
    }
    path = directory / f"team_{robots}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def summary(values: Sequence[float], scale: float = 1e3) -> dict[str, Any]:
    """n, median, p90 and max, in milliseconds."""
    ordered = sorted(values)
    p90 = ordered[min(len(ordered) - 1, int(0.9 * len(ordered)))]
    return {
        "n": len(ordered),
        "median_ms": round(statistics.median(ordered) * scale, 3),
        "p90_ms": round(p90 * scale, 3),
        "max_ms": round(ordered[-1] * scale, 3),
    }


def running_event(
    op: Operator, since: int, skill_id: str, timeout: float = 10.0
) -> tuple[float, float]:
    """(arrival here, robot's started stamp) of the event that shows ``skill_id`` RUNNING."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for arrived, event in op.events.since(since):
            for placed in event.put_skills:
                if placed.skill.id == skill_id and placed.skill.status.value == S.RUNNING:
                    return arrived, placed.skill.started
        time.sleep(0.002)
    raise RuntimeError(f"{skill_id} never showed RUNNING")


def sync_to_start(op: Operator, agent: str, samples: int) -> dict[str, Any]:
    """Synchronize one short skill at a time to a started, idle robot."""
    op.start(agent)
    to_robot, to_operator, call = [], [], []
    for _ in range(samples):
        skill_id = op.add(agent, "wait", {"duration": 0.01})
        revision = op.call("get_mission").mission.revision
        since = len(op.events)
        called = time.time()
        op.call("synchronize", base_revision=revision, agent=agent, upto_id="")
        returned = time.time()
        arrived, started = running_event(op, since, skill_id)
        to_robot.append(started - returned)
        to_operator.append(arrived - returned)
        call.append(returned - called)
        op.wait_status([skill_id], S.SUCCESS)
    return {
        "robot_running_after_return": summary(to_robot),
        "operator_sees_running_after_return": summary(to_operator),
        "synchronize_call": summary(call),
        "note": "negative: the robot started before the service answer reached the operator",
    }


def barrier_rounds(op: Operator, agents: Sequence[str], rounds: int) -> tuple[list[list[str]], str]:
    """Barriers of all ``agents``; the robots arrive 20 ms apart.

    Returns the members of every completed round, and why the rounds stopped early
    ("" if they did not).
    """
    out = []
    for number in range(rounds):
        for index, agent in enumerate(agents):
            op.add(agent, "wait", {"duration": 0.02 * (index + 1)})
        members = [op.add(agent, "wait", {"duration": 0.02}) for agent in agents]
        op.add_barrier(members)
        for agent in agents:
            op.sync(agent)
        try:
            state = op.wait_status(members, S.SUCCESS, timeout=30.0)
        except AssertionError:
            state = op.mission()
            behind = [m for m in members if state.skill(m).status is not S.SUCCESS]
            return out, (
                f"round {number + 1}: the ground never saw {', '.join(behind)} finish "
                "(a robot's report stream stalled; see the executor test report)"
            )
        out.append(members)
    return out, ""


def executor_figures(
    env: dict[str, str], work: Path, library: Path, sizes: Sequence[int], samples: int, rounds: int
) -> dict[str, Any]:
    """Sync-to-start latency and barrier skew with ``max(sizes)`` robots."""
    agents = [f"a{i:02d}" for i in range(1, max(sizes) + 1)]
    system = RosmcSystem(env, work / "robots", library=library)
    operator = None
    try:
        system.start_server()
        started = time.monotonic()
        for agent in agents:
            system.start_executor(agent)
        operator = Operator(timeout=60.0)
        operator.wait_links(agents, timeout=180.0)
        startup = time.monotonic() - started
        latency = sync_to_start(operator, agents[0], samples)
        operator.start()
        barriers: dict[int, list[list[str]]] = {}
        stalls: dict[str, str] = {}
        for size in sizes:
            barriers[size], stall = barrier_rounds(operator, agents[:size], rounds)
            if stall:
                stalls[f"{size}_robots"] = stall
                break  # that robot's link stays stalled
        operator.close()
        operator = None
        system.stop("server")
        stamps = running_stamps(system.journal)
        skew = {
            f"{size}_robots": summary(
                [max(stamps[m] for m in b) - min(stamps[m] for m in b) for b in runs]
            )
            for size, runs in barriers.items()
            if runs
        }
        figures: dict[str, Any] = {
            "executors_started_s": round(startup, 1),
            "sync_to_start": latency,
            "barrier_skew": skew,
        }
        if stalls:
            figures["stalled"] = stalls
        return figures
    finally:
        if operator is not None:
            operator.close()
        system.close()


def outage_figures(env: dict[str, str], work: Path, library: Path, rounds: int) -> dict[str, Any]:
    """Three robots behind the emulator finish three skills each during a blackout."""
    agents = ["a01", "a02", "a03"]
    system = RosmcSystem(env, work / "outage", library=library)
    operator = None
    try:
        system.start_server("_link_timeout:=1.0")
        system.start_emulator(agents)
        for agent in agents:
            system.start_executor(agent, robot_side=True)
        operator = Operator(timeout=60.0)
        operator.wait_links(agents, timeout=60.0)
        delays = []
        for _ in range(rounds):
            skills = {
                a: [operator.add(a, "wait", {"duration": 0.3}) for _ in range(3)] for a in agents
            }
            for agent in agents:  # held until all are uploaded, then started together
                operator.control(agent, srv.ControlRequest.STOP)
                operator.sync(agent)
            operator.wait_status([i for ids in skills.values() for i in ids], S.IDLE_SYNCHRONIZED)
            for agent in agents:
                operator.start(agent)
            firsts = [ids[0] for ids in skills.values()]
            operator.wait_status(firsts, S.RUNNING)
            for agent in agents:
                operator.blackout(agent, True)
            time.sleep(2.0)  # everything finishes (0.9 s), and the links go DOWN (1 s)
            everything = {i for ids in skills.values() for i in ids}
            shown = {
                s.id
                for s in operator.mission().skills()
                if s.id in everything and s.status is S.SUCCESS
            }
            since = len(operator.events)
            restored = time.time()
            for agent in agents:
                operator.blackout(agent, False)
            deadline = time.monotonic() + 30.0
            last = restored
            while shown != everything:
                if time.monotonic() > deadline:
                    raise RuntimeError(f"still missing: {everything - shown}")
                time.sleep(0.005)
                for arrived, event in operator.events.since(since):
                    for placed in event.put_skills:
                        if placed.skill.status.value == S.SUCCESS and placed.skill.id in everything:
                            shown.add(placed.skill.id)
                            last = max(last, arrived)
            delays.append(last - restored)
        return {
            "robots": len(agents),
            "skills_finished_during_outage": 9,
            "restore_to_all_success": summary(delays),
        }
    finally:
        if operator is not None:
            operator.close()
        system.close()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=20, help="sync-to-start samples")
    parser.add_argument("--rounds", type=int, default=10, help="barrier rounds per team size")
    parser.add_argument("--robots", default="2,5,20", help="barrier team sizes")
    parser.add_argument("--outages", type=int, default=3, help="blackout rounds")
    parser.add_argument("--keep", action="store_true", help="keep the work directory")
    args = parser.parse_args(argv)
    sizes = sorted({int(n) for n in args.robots.split(",")})
    work = Path(tempfile.mkdtemp(prefix="bench_executor_"))
    began = time.monotonic()
    try:
        (work / "home" / "log").mkdir(parents=True)
        library = team_library(work, max(max(sizes), 3))
        with ros_master(work / "home") as env:
            figures = executor_figures(env, work, library, sizes, args.samples, args.rounds)
            figures["report_delivery_after_outage"] = outage_figures(
                env, work, library, args.outages
            )
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print_figures(figures, began)
    return 0


def print_figures(figures: dict[str, Any], began: float) -> None:
    """Print ``figures`` as JSON with the machine and the wall time since ``began``."""
    figures["machine"] = {
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_1min_at_end": round(os.getloadavg()[0], 2),  # other work skews figures
    }
    figures["wall_time_s"] = round(time.monotonic() - began, 1)
    print(json.dumps(figures, indent=2))


if __name__ == "__main__":
    sys.exit(main())
