"""The site facts of the docs are the simulator's: positions, sizes, starts and Wi-Fi coverage.

Reads the tables of docs/operator-guide.md's "The simulated site" section and compares them with the
scenario file the simulator loads, and the coverage column with the simulator's own radio
model (range and line of sight through the pybullet bodies of the obstacles).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

from rosmc_sim.core.coverage import coverage_by_region
from rosmc_sim.core.scenario import Scenario, load_scenario
from rosmc_sim.core.sim import Simulation
from rosmc_sim.core.world import World

REPO = Path(__file__).resolve().parents[2]
SCENARIO = REPO / "rosmc_sim" / "scenarios" / "mars_sample_return.yaml"
NUMBER = r"-?\d+(?:\.\d+)?"
POINT = re.compile(rf"\(({NUMBER}), ({NUMBER})\)")


def site_section() -> str:
    """The operator guide's site section, with typographic minus signs made ASCII."""
    text = (REPO / "docs" / "operator-guide.md").read_text().replace("−", "-")
    start = text.index("## The simulated site")
    return text[start : text.index("\n## ", start + 1)]


def table_with(section: str, header_cell: str) -> list[list[str]]:
    """The table whose header starts with ``header_cell``."""
    text = section.split("\n")
    for index, line in enumerate(text):
        if line.startswith(f"| {header_cell}"):
            block = list(_rows(text[index:]))
            return block[2:]
    raise AssertionError(f"no table starting with {header_cell!r} in the site section")


def _rows(lines: list[str]) -> Iterator[list[str]]:
    for line in lines:
        if not line.startswith("|"):
            return
        yield [cell.strip() for cell in line.strip().strip("|").split("|")]


def points(text: str) -> list[tuple[float, float]]:
    """Every ``(x, y)`` in ``text``."""
    return [(float(x), float(y)) for x, y in POINT.findall(text)]


def metres(text: str, pattern: str) -> float:
    """The number before or after which ``pattern`` (with ``{}`` for it) stands."""
    match = re.search(pattern.format(f"({NUMBER})"), text)
    assert match, f"{pattern!r} not in {text!r}"
    return float(match.group(1))


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    """The scenario the simulator loads by default."""
    return load_scenario(SCENARIO)


@pytest.fixture(scope="module")
def coverage(scenario: Scenario) -> Iterator[dict[str, float]]:
    """Each region's covered share at the start, by the simulator's radio model."""
    world = World(scenario)
    try:
        yield coverage_by_region(Simulation(scenario, world))
    finally:
        world.close()


def test_the_lander_and_the_objects_on_the_site_are_where_the_scenario_puts_them(
    scenario: Scenario,
) -> None:
    rows = table_with(site_section(), "where (x, y in m) |")
    lander = next(what for where, what in rows if "**lander**" in what)
    assert metres(lander, "{} m across") == 2 * scenario.lander_radius
    assert metres(lander, "within {} m") == scenario.charge_radius
    assert metres(lander, "Wi-Fi reaches {} m") == scenario.lander_wifi_radius
    boxes = next(what for where, what in rows if "payload boxes" in what)
    wifi_box = next(b for b in scenario.boxes if b.kind == "wifi")
    assert metres(boxes, "adds {} m") == wifi_box.wifi_radius
    assert [b.name for b in scenario.boxes] == re.findall(r"`(\w+_box)`", boxes)
    stated = {p for where, _ in rows for p in points(where)}
    placed = {(0.0, 0.0)} | {(b.x, b.y) for b in scenario.boxes}
    placed |= {(o.x, o.y) for o in scenario.obstacles} | {(s.x, s.y) for s in scenario.slopes}
    assert stated == placed


def test_the_regions_and_their_wifi_coverage_match_the_simulator(
    scenario: Scenario, coverage: dict[str, float]
) -> None:
    rows = table_with(site_section(), "region | centre")
    assert [row[0] for row in rows] == [r.name for r in scenario.regions]
    for (name, centre, radius, stones, best, wifi), region in zip(
        rows, scenario.regions, strict=True
    ):
        assert points(centre) == [(region.x, region.y)], name
        assert metres(radius, "{} m") == region.radius, name
        assert (int(stones), float(best)) == (region.stones, region.max_score), name
        stated = metres(wifi, "{} %")
        assert abs(stated - 100 * coverage[name]) <= 1.0, (name, stated, coverage[name])


def test_the_robots_start_where_the_scenario_puts_them(scenario: Scenario) -> None:
    rows = table_with(site_section(), "robot | starts at")
    assert {name: points(where)[0] for name, where in rows} == {
        r.name: (r.x, r.y) for r in scenario.robots
    }
