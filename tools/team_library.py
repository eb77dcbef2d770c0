"""Write the skill library of a scenario's team: the Mars team's models, the scenario's robots.

A library names its agents, and ``extends`` can add agents but never drop the base's three
robots; a team of other robots on the same models is therefore a library of its own. It is
made from ``rosmc_server/config/mars_team.yaml`` (its text kept as it is, so its comments
stay) with the ``agents:`` block replaced: one dynamic agent per robot of the scenario on its
kind's model, and the base's static agents (lander, boxes). ``tests/unit/test_team_library.py``
checks that the shipped ``mars_twenty_robots.yaml`` is what this makes::

    python tools/team_library.py rosmc_sim/scenarios/twenty_robots.yaml mars_twenty_robots \\
        > rosmc_server/config/mars_twenty_robots.yaml
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from rosmc_sim.core.scenario import load_scenario  # noqa: E402

BASE = REPO / "rosmc_server" / "config" / "mars_team.yaml"
MODELS = {"drone": "drone_scout", "science_rover": "rover_science"}
MODELS["manipulator_rover"] = "rover_manipulator"
DESCRIPTIONS = {"drone": "Aerial scout.", "science_rover": "Science rover."}
DESCRIPTIONS["manipulator_rover"] = "Rover with an arm."


def team_library(scenario: Path, name: str) -> str:
    """The library text for the robots of ``scenario``, named ``name``."""
    base = BASE.read_text(encoding="utf-8")
    head, _, agents = base.partition("\nagents:\n")
    static = [line for line in agents.splitlines() if "kind: static" in line]
    robots = [
        f"  {robot.name}: {{kind: dynamic, model: {MODELS[robot.kind]}, "
        f"description: {DESCRIPTIONS[robot.kind]}}}"
        for robot in load_scenario(scenario).robots
    ]
    scenario_name = scenario.relative_to(REPO) if scenario.is_relative_to(REPO) else scenario
    header = (
        f"# Made by tools/team_library.py from mars_team.yaml and {scenario_name}: edit those.\n"
    )
    head = head.replace("\nname: mars_sample_return\n", f"\nname: {name}\n", 1)
    return header + head + "\nagents:\n" + "\n".join(robots + static) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", type=Path)
    parser.add_argument("name")
    args = parser.parse_args()
    sys.stdout.write(team_library(args.scenario.resolve(), args.name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
