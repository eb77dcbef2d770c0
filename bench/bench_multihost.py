"""Benchmark of the robot link across hosts (network namespaces); prints one JSON object.

Builds a :class:`~tests.integration.netns.RadioLab`: ``rosmaster``, the mission server and
the operator in a ground namespace, every robot's executor in a namespace of its own,
talking to the server and to each other over its "radio" (a veth pair into a bridge on the
ground; no link emulator). Measured at full speed, then with every radio limited to
``--rate`` by ``tc tbf`` (both directions):

* ``sync_to_start``: from the operator's Synchronize call returning to the skill RUNNING
  on a started, idle robot (the robot's RUNNING stamp), and to the operator seeing it on
  ``/rosmc/mission_events`` (``bench_executor.sync_to_start``, run by the operator on the
  ground);
* ``barrier_skew``: max - min of the members' RUNNING stamps, per barrier of all robots,
  which arrive 20 ms apart (``bench_executor.barrier_rounds``);
* ``idle_radio``: bytes per second each way on every robot's radio while nothing happens
  (heartbeats, beacons and the robot's periodic snapshot, whose digest stands in for its
  queue), with the number of skills it holds (the first robot: 100).

Then, still at ``--rate`` and with the kernel's default TCP settings, the radio cuts of
docs/barriers.md, ``--outages`` times each (``ip link set down``, back ``--outage`` s later):

* ``cut_while_members_approach``: every radio goes down while all members run towards
  the barrier, so each arrives during the cut;
* ``partner_cut_before_arrival``: two robots; the first waits, the second's radio goes
  down 0.7 s before it arrives (it heard the first arrive; the first cannot hear it);
* ``every_radio_cut_during_release``: every member but the last waits; all radios go
  down as the last arrives.

For each: the members' start skew, the time from the radios' return to the first and the
last member starting (a negative first start would be a member that started during the
cut: ``started_during_cut`` counts them, and must stay 0).

All namespaces share one kernel, hence one clock: the robots' stamps, the operator's and
this script's are directly comparable. Needs root; without it (or where namespaces are
refused) it prints ``{"skipped": reason}``. Run from the repository root after
``source env.sh``::

    python bench/bench_multihost.py [--robots 3] [--samples 20] [--rounds 10]
                                    [--rate 256kbit] [--outages 3] [--outage 15]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from bench_executor import print_figures, summary, team_library  # noqa: E402

from tests.integration.barrier_cuts import (  # noqa: E402
    CutOutcome,
    cut_while_members_approach,
    every_radio_cut_during_release,
    partner_cut_before_arrival,
)
from tests.integration.multihost_fixtures import LabSystem, lab_base_env  # noqa: E402
from tests.integration.netns import RadioLab, unavailable  # noqa: E402
from tests.integration.remote_operator import RemoteOperator  # noqa: E402

MEASURES = "bench.bench_executor"  # run by the operator, next to the server


def link_figures(
    op: RemoteOperator, agents: Sequence[str], samples: int, rounds: int
) -> dict[str, Any]:
    """Sync-to-start latency on the first robot and barrier skew across all of them."""
    latency = op(f"{MEASURES}:sync_to_start", agents[0], samples, timeout=30.0 + samples * 5.0)
    barriers, stall = op(f"{MEASURES}:barrier_rounds", list(agents), rounds, timeout=40.0 * rounds)
    started = op("started")
    skews = [max(started[m] for m in b) - min(started[m] for m in b) for b in barriers]
    figures: dict[str, Any] = {"sync_to_start": latency}
    if skews:
        figures["barrier_skew"] = summary(skews)
    if stall:
        figures["stalled"] = stall
    return figures


def hold_skills(op: RemoteOperator, agent: str, total: int) -> None:
    """Have ``agent``'s robot hold ``total`` skills (quick ones, run to the end)."""
    held = sum(1 for _, _, owner in op("statuses").values() if owner == agent)
    added = [op("add", agent, "wait", {"duration": 0.01}) for _ in range(total - held)]
    if added:
        op("sync", agent)
        op("wait_status", added, "SUCCESS", 120.0, timeout=130.0)


def idle_radio(
    op: RemoteOperator, lab: RadioLab, agents: Sequence[str], seconds: float
) -> dict[str, Any]:
    """What every idle robot's radio carries per second, and how many skills the robot holds."""
    before = {agent: lab.sent_bytes(agent) for agent in agents}
    time.sleep(seconds)
    after = {agent: lab.sent_bytes(agent) for agent in agents}
    held = Counter(agent for _, _, agent in op("statuses").values())
    return {
        agent: {
            "skills_on_robot": held[agent],
            "downlink_bytes_per_s": round((after[agent][0] - before[agent][0]) / seconds),
            "uplink_bytes_per_s": round((after[agent][1] - before[agent][1]) / seconds),
        }
        for agent in agents
    }


def cut_figures(outcomes: Sequence[CutOutcome], outage: float) -> dict[str, Any]:
    """Skew and restore-to-start figures over repeated runs of one cut scenario."""
    return {
        "outage_s": outage,
        "started_during_cut": sum(1 for o in outcomes for t in o.starts.values() if t < o.restored),
        "barrier_skew": summary([o.skew for o in outcomes]),
        "restore_to_first_start": summary([o.first_after_restore for o in outcomes]),
        "restore_to_last_start": summary([o.last_after_restore for o in outcomes]),
    }


def barrier_cut_figures(
    op: RemoteOperator, lab: RadioLab, agents: Sequence[str], runs: int, outage: float
) -> dict[str, Any]:
    """Every cut scenario of docs/barriers.md, ``runs`` times each."""
    scenarios = {
        "cut_while_members_approach": lambda: cut_while_members_approach(op, lab, agents, outage),
        "partner_cut_before_arrival": lambda: partner_cut_before_arrival(
            op, lab, agents[0], agents[1], outage
        ),
        "every_radio_cut_during_release": lambda: every_radio_cut_during_release(
            op, lab, agents, outage
        ),
    }
    return {
        name: cut_figures([run() for _ in range(runs)], outage) for name, run in scenarios.items()
    }


@contextlib.contextmanager
def team(args: argparse.Namespace, work: Path) -> Iterator[tuple[RadioLab, RemoteOperator, float]]:
    """A lab of ``args.robots`` robots, linked and executing: (lab, operator, start-up seconds).

    The hosts keep the kernel's default TCP settings.
    """
    agents = [f"a{i:02d}" for i in range(1, args.robots + 1)]
    work.mkdir(parents=True)
    library = team_library(work, args.robots)
    with RadioLab(agents, subnet=os.getpid() % 250) as lab:
        system = LabSystem(lab_base_env(work / "home"), work / "team", library=library, lab=lab)
        try:
            system.start_master()
            system.start_server("_link_timeout:=2.0")
            began = time.monotonic()
            for agent in agents:
                system.start_executor(agent)
            op = system.operator()
            op("wait_links", agents, 120.0, timeout=130.0)
            startup = time.monotonic() - began
            op("start", "")
            yield lab, op, startup
        finally:
            system.close()


def measure(args: argparse.Namespace, work: Path) -> dict[str, Any]:
    """Every figure, in one lab with the kernel's default TCP settings."""
    with team(args, work / "default") as (lab, op, startup):
        agents = list(lab.robots)
        figures: dict[str, Any] = {
            "robots": args.robots,
            "executors_started_s": round(startup, 1),
            "full_speed": link_figures(op, agents, args.samples, args.rounds),
        }
        lab.shape(args.rate)
        figures[f"tbf_{args.rate}"] = link_figures(op, agents, args.samples, args.rounds)
        hold_skills(op, agents[0], 100)  # the snapshot's digest stands in for the queue
        figures["idle_radio"] = idle_radio(op, lab, agents, 5.0)
        figures["radio_cuts"] = barrier_cut_figures(op, lab, agents, args.outages, args.outage)
    return figures


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=3, help="robots, one namespace each")
    parser.add_argument("--samples", type=int, default=20, help="sync-to-start samples")
    parser.add_argument("--rounds", type=int, default=10, help="barrier rounds")
    parser.add_argument("--rate", default="256kbit", help="tbf rate of every radio")
    parser.add_argument("--outages", type=int, default=3, help="runs of each cut scenario")
    parser.add_argument("--outage", type=float, default=15.0, help="seconds each cut lasts")
    parser.add_argument("--keep", action="store_true", help="keep the work directory")
    return run_in_lab(parser.parse_args(argv), measure, "bench_multihost_")


def run_in_lab(
    args: argparse.Namespace,
    measure: Callable[[argparse.Namespace, Path], dict[str, Any]],
    prefix: str,
) -> int:
    """Print ``measure(args, work)``'s figures, or ``{"skipped": reason}`` without namespaces.

    ``work`` is a new folder, removed afterwards unless ``args.keep``.
    """
    reason = unavailable()
    if reason:
        print(json.dumps({"skipped": reason}))
        return 0
    work = Path(tempfile.mkdtemp(prefix=prefix))
    began = time.monotonic()
    try:
        figures = measure(args, work)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    print_figures(figures, began)
    return 0


if __name__ == "__main__":
    sys.exit(main())
