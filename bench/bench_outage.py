"""Benchmark of operator commands to robots out of contact; prints one JSON object.

Starts its own ``rosmaster`` on a free port (private ``ROS_HOME``), a mission server, the
link emulator and three executor processes behind it. Each round blacks out every robot's
link, waits until the server calls the links DOWN, and then operates every robot as if it
were in contact: synchronize two skills, take the second back, change the lost-link policy
twice, start. It then ends the blackout and waits until the first skill of every robot has
run. It reports:

* ``refused``: operator commands the server refused (want 0: out of contact is no reason);
* ``contact_to_delivery``: from the end of a blackout to each held command's acknowledgement
  arriving on the ground (the journal's ``/rosmc/robot_commands`` records), p50/p95/max;
* ``max_waiting_per_robot``: the most commands shown waiting for one robot (agent states);
* ``delivered_held_per_round``: held commands delivered per round and robot (want 3: the
  upload of one skill, the last policy and the start; the take-back and the first policy
  never leave).

Run from the repository root after ``source env.sh``::

    python bench/bench_outage.py [--rounds N]
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
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import rosmc.msg as wire
import rosmc.srv as srv
import rospy

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

from _server_harness import ros_master  # noqa: E402

from rosmc_server import interface  # noqa: E402
from rosmc_server.conversions import policy_to_request  # noqa: E402
from rosmc_server.core import LostLinkKind, LostLinkPolicy, SkillStatus  # noqa: E402
from rosmc_server.recording import read_journal  # noqa: E402
from tests.conftest import wait_until  # noqa: E402
from tests.integration.executor_fixtures import Operator, OperatorError, RosmcSystem  # noqa: E402

AGENTS = ("r1", "r2", "r3")


class WaitingWatch:
    """The most commands ``/rosmc/agent_states`` showed waiting per robot, and link states."""

    def __init__(self) -> None:
        self.most: dict[str, int] = dict.fromkeys(AGENTS, 0)
        self.links: dict[str, int] = {}
        self._lock = threading.Lock()
        self._subscriber = rospy.Subscriber(
            interface.AGENT_STATES_TOPIC, wire.AgentStates, self._on_states, queue_size=10
        )

    def _on_states(self, msg: wire.AgentStates) -> None:
        with self._lock:
            for state in msg.agents:
                waiting = state.link.commands_waiting
                self.most[state.agent] = max(self.most.get(state.agent, 0), waiting)
                self.links[state.agent] = state.link.state

    def all_down(self) -> bool:
        """Whether the server calls every robot's link DOWN."""
        with self._lock:
            return all(self.links.get(a) == wire.LinkState.DOWN for a in AGENTS)

    def close(self) -> None:
        """Stop listening."""
        self._subscriber.unregister()


def percentile(values: Sequence[float], share: float) -> float:
    """The value below which ``share`` of ``values`` lie (nearest rank)."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(share * len(ordered)))]


def operate(op: Operator, agent: str, skills: Sequence[str]) -> int:
    """Everything an operator does to one robot while it is out of contact; refusals."""
    refused = 0
    calls = [
        lambda: op.change("synchronize", agent=agent, upto_id=""),
        lambda: op.change("unsynchronize", agent=agent, from_id=skills[1]),
        *(
            lambda after=after: op.call(
                "set_lost_link_policy",
                agent=agent,
                **policy_to_request(LostLinkPolicy(LostLinkKind.HOLD, after=after), []),
            )
            for after in (60.0, 90.0)
        ),
        lambda: op.call("control", agent=agent, command=srv.ControlRequest.START),
    ]
    for call in calls:
        try:
            call()
        except OperatorError:
            refused += 1
    return refused


def outage_rounds(env: dict[str, str], work: Path, rounds: int) -> dict[str, Any]:
    """Run the rounds; the figures."""
    system = RosmcSystem(env, work / "system")
    op = watch = None
    try:
        system.start_server("_link_timeout:=1.0")
        system.start_emulator(AGENTS)
        for agent in AGENTS:
            system.start_executor(agent, robot_side=True)
        op = Operator(timeout=60.0)
        op.wait_links(AGENTS, timeout=60.0)
        watch = WaitingWatch()
        refused = 0
        restores: list[float] = []
        for _ in range(rounds):
            skills = {a: [op.add(a, "wait", {"duration": 0.05}) for _ in range(2)] for a in AGENTS}
            for agent in AGENTS:
                op.blackout(agent, True)
            wait_until(watch.all_down, 30.0, "every link DOWN")
            for agent in AGENTS:
                refused += operate(op, agent, skills[agent])
            time.sleep(1.0)  # the waiting work is shown (agent states at 2 Hz)
            restores.append(time.time())
            for agent in AGENTS:
                op.blackout(agent, False)
            op.wait_status([ids[0] for ids in skills.values()], SkillStatus.SUCCESS, timeout=60.0)
        system.stop("server")
        return figures(system.journal, restores, refused, watch.most, rounds)
    finally:
        if watch is not None:
            watch.close()
        if op is not None:
            op.close()
        system.close()


def figures(
    journal: Path, restores: list[float], refused: int, most: dict[str, int], rounds: int
) -> dict[str, Any]:
    """The figures from the journal's command records."""
    records = [r.message for r in read_journal(journal, [interface.ROBOT_COMMANDS_TOPIC]).records]
    held = [m for m in records if m.held and m.event == wire.CommandRecord.DELIVERED]
    delays = []
    for record in held:
        delivered = record.delivered.to_sec()
        restored = max((t for t in restores if t <= delivered), default=None)
        if restored is not None:
            delays.append(delivered - restored)
    per_robot = {a: sum(1 for m in held if m.agent == a) / rounds for a in AGENTS}
    return {
        "robots": len(AGENTS),
        "rounds": rounds,
        "refused": refused,
        "contact_to_delivery": {
            "n": len(delays),
            "p50_ms": round(statistics.median(delays) * 1e3, 1) if delays else None,
            "p95_ms": round(percentile(delays, 0.95) * 1e3, 1) if delays else None,
            "max_ms": round(max(delays) * 1e3, 1) if delays else None,
        },
        "max_waiting_per_robot": max(most.values()),
        "delivered_held_per_round": per_robot,
    }


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="blackout rounds")
    parser.add_argument("--keep", action="store_true", help="keep the work directory")
    args = parser.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="bench_outage_"))
    began = time.monotonic()
    try:
        (work / "home" / "log").mkdir(parents=True)
        with ros_master(work / "home") as env:
            result = outage_rounds(env, work, args.rounds)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    result["machine"] = {
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_1min_at_end": round(os.getloadavg()[0], 2),
    }
    result["wall_time_s"] = round(time.monotonic() - began, 1)
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
