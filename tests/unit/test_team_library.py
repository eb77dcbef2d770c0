"""The shipped 20-robot library is what tools/team_library.py makes from its sources."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from rosmc_server.core import load_library
from rosmc_sim.core.scenario import load_scenario

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "rosmc_sim" / "scenarios" / "twenty_robots.yaml"
LIBRARY = REPO / "rosmc_server" / "config" / "mars_twenty_robots.yaml"


def test_the_twenty_robot_library_is_made_from_the_mars_team_and_the_scenario() -> None:
    spec = importlib.util.spec_from_file_location(
        "team_library", REPO / "tools" / "team_library.py"
    )
    assert spec is not None and spec.loader is not None
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    made = tool.team_library(SCENARIO, "mars_twenty_robots")
    assert LIBRARY.read_text(encoding="utf-8") == made, (
        "run: python tools/team_library.py rosmc_sim/scenarios/twenty_robots.yaml "
        "mars_twenty_robots > rosmc_server/config/mars_twenty_robots.yaml"
    )
    library = load_library(LIBRARY)
    assert sorted(library.dynamic_agents) == sorted(r.name for r in load_scenario(SCENARIO).robots)
