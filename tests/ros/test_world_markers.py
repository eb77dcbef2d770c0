"""The site's rviz markers (``/rosmc/sim/world``) as messages: a ground rviz can pick,
region labels beside their discs. No master; rviz itself is driven in
``tests/integration/test_rviz_mouse.py``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
import yaml
from visualization_msgs.msg import Marker

from rosmc_sim.core.scenario import load_scenario
from rosmc_sim.core.sim import Simulation
from rosmc_sim.ros.topics import WORLD_TOPIC
from rosmc_sim.ros.world_markers import world_markers

REPO = Path(__file__).resolve().parents[2]
SCENARIOS = sorted((REPO / "rosmc_sim" / "scenarios").glob("*.yaml"))
CONFIGS = [REPO / "rviz" / "operator.rviz", REPO / "rviz" / "sim.rviz"]


@pytest.fixture(scope="module", params=SCENARIOS, ids=[p.stem for p in SCENARIOS])
def sim(request: pytest.FixtureRequest) -> Simulation:
    return Simulation(load_scenario(request.param))


def by_ns(sim: Simulation, ns: str) -> list[Marker]:
    return [m for m in world_markers(sim).markers if m.ns == ns]


def hidden_namespaces(config: Path) -> set[str]:
    """The namespaces of the site's display that a config switches off."""
    document: dict[str, Any] = yaml.safe_load(config.read_text())
    for display in document["Visualization Manager"]["Displays"]:
        if display.get("Marker Topic") == WORLD_TOPIC:
            return {ns for ns, shown in (display.get("Namespaces") or {}).items() if not shown}
    raise AssertionError(f"{config} shows no {WORLD_TOPIC}")


@pytest.mark.parametrize("config", CONFIGS, ids=[c.stem for c in CONFIGS])
def test_a_pickable_ground_covers_the_site_and_is_shown(sim: Simulation, config: Path) -> None:
    (slab,) = by_ns(sim, "pick_ground")
    assert "pick_ground" not in hidden_namespaces(config)
    x_min, x_max, y_min, y_max = sim.scenario.bounds
    assert slab.type == Marker.CUBE and slab.color.a > 0.0  # rviz skips what has no alpha
    assert (slab.scale.x, slab.scale.y) == (x_max - x_min, y_max - y_min)
    assert (slab.pose.position.x, slab.pose.position.y) == (
        (x_min + x_max) / 2,
        (y_min + y_max) / 2,
    )
    top = slab.pose.position.z + slab.scale.z / 2
    assert -0.05 < top <= 0.0, "its top is the ground, just under the grid"


def test_region_labels_stand_beside_their_discs(sim: Simulation) -> None:
    for region in sim.regions.values():
        region.discovered = True
    labels = by_ns(sim, "region_labels")
    assert len(labels) == len(sim.regions)
    for label, region in zip(labels, sim.regions.values(), strict=True):
        spec = region.spec
        assert label.text.startswith(spec.name)
        distance = math.hypot(label.pose.position.x - spec.x, label.pose.position.y - spec.y)
        assert distance > spec.radius, f"{spec.name}'s label covers its disc"
