"""What an idle robot's radio carries, all protocols counted; prints one JSON object.

Builds a :class:`~tests.integration.netns.RadioLab` of one ground and ``--robots`` robots
(``rosmaster``, the mission server and the operator on the ground, each executor on its
own host, no link emulator), starts the robots, has the first one run ``--skills`` quick
skills to the end (so it holds them all), waits ``--settle`` s, and then, over
``--seconds`` s with nothing happening:

* ``uplink_bytes_per_s`` / ``downlink_bytes_per_s``: what the first robot's radio sent
  and received (the ``tc`` counters of its interface: whole Ethernet frames, every
  protocol: topics, the radio side channel, the ROS master's XML-RPC, TCP's own acks);
  ``uplink_kbit_per_s`` the same in kbit/s (the target: under 2);
* ``uplink_by_kind``: the robot's sent frames sorted by kind (``bench/_sniff.py``).

The figure is the idle robot's own: the ground has nothing to ask it. Needs root (network
namespaces); without it prints ``{"skipped": reason}``. From the repository root after
``source env.sh``::

    python bench/bench_idle_link.py [--robots 1] [--skills 100] [--seconds 20]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

from bench_executor import team_library  # noqa: E402
from bench_multihost import hold_skills, run_in_lab  # noqa: E402

from tests.integration.multihost_fixtures import LabSystem, lab_base_env  # noqa: E402
from tests.integration.netns import ROBOT_RADIO, RadioLab  # noqa: E402

RATE = "10mbit"  # shaped only for the interface's counters: nothing idle comes near it


def idle_figures(lab: RadioLab, agent: str, seconds: float) -> dict[str, Any]:
    """What ``agent``'s radio carries per second over ``seconds``, and by kind."""
    sniffer = subprocess.Popen(
        lab.command(agent, [sys.executable, str(REPO / "bench" / "_sniff.py"), ROBOT_RADIO,
                            str(seconds)]),
        stdout=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    before = lab.sent_bytes(agent)
    time.sleep(seconds)
    after = lab.sent_bytes(agent)
    kinds, _ = sniffer.communicate(timeout=seconds + 30.0)
    uplink = (after[1] - before[1]) / seconds
    return {
        "seconds": seconds,
        "uplink_bytes_per_s": round(uplink),
        "uplink_kbit_per_s": round(uplink * 8 / 1000, 2),
        "downlink_bytes_per_s": round((after[0] - before[0]) / seconds),
        "uplink_by_kind": json.loads(kinds) if kinds.strip() else None,
    }


def measure(args: argparse.Namespace, work: Path) -> dict[str, Any]:
    """Start the team, make the first robot hold the skills, measure it idle."""
    agents = [f"a{i:02d}" for i in range(1, args.robots + 1)]
    library = team_library(work, args.robots)
    with RadioLab(agents, subnet=os.getpid() % 250) as lab:
        system = LabSystem(lab_base_env(work / "home"), work / "team", library=library, lab=lab)
        try:
            system.start_master()
            system.start_server()
            for agent in agents:
                system.start_executor(agent)
            op = system.operator()
            op("wait_links", agents, 120.0, timeout=130.0)
            op("start", "")
            hold_skills(op, agents[0], args.skills)
            lab.shape(RATE)
            time.sleep(args.settle)
            figures = idle_figures(lab, agents[0], args.seconds)
            held = sum(1 for _, _, owner in op("statuses").values() if owner == agents[0])
            links = op("links", agents)
        finally:
            system.close()
    return {"robots": args.robots, "skills_on_robot": held, "links": links, **figures}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the benchmark and print its JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=1, help="robots, one namespace each")
    parser.add_argument("--skills", type=int, default=100, help="skills the first robot holds")
    parser.add_argument("--settle", type=float, default=60.0, help="seconds idle before measuring")
    parser.add_argument("--seconds", type=float, default=30.0, help="seconds measured")
    parser.add_argument("--keep", action="store_true", help="keep the work directory")
    return run_in_lab(parser.parse_args(argv), measure, "bench_idle_link_")


if __name__ == "__main__":
    sys.exit(main())
