"""How rviz shows radio coverage: cells shaded by signal, and each robot's last-link mark.

Pure geometry and colour over a :class:`~rosmc_server.core.robots.radio_map.RadioMap`: the radio
model's prediction (faint, flat, only where it reaches), the robots' own readings (stronger,
a little higher, faded once older than :data:`OLD_AFTER`), and where each robot last had a
link, labelled with its reading and age ("-72 dBm 26 s ago").
"""

from __future__ import annotations

from dataclasses import dataclass

from rosmc_server.core.robots.radio_map import RadioMap, reading_text
from rosmc_server.core.views.geometry import Color

STRONG, WEAK = -50.0, -90.0  # dBm shaded full green and full red
OLD_AFTER = 10.0  # seconds: a reading older than this is shown as old
MODEL_ALPHA, MEASURED_ALPHA, OLD_ALPHA = 0.3, 0.75, 0.35
UNCOVERED = Color(0.35, 0.35, 0.38)


@dataclass(frozen=True)
class Cell:
    """One shaded square: centre, side and colour."""

    x: float
    y: float
    size: float
    color: Color


@dataclass(frozen=True)
class LastLink:
    """Where a robot last had a link, and what to write there."""

    agent: str
    x: float
    y: float
    label: str
    old: bool


def signal_color(dbm: float, covered: bool, alpha: float) -> Color:
    """Green for a strong signal through yellow to red at the edge; grey where not covered."""
    if not covered:
        return UNCOVERED.with_alpha(alpha)
    t = min(1.0, max(0.0, (dbm - WEAK) / (STRONG - WEAK)))  # 0 weak .. 1 strong
    return Color(min(1.0, 2.0 * (1.0 - t)), min(1.0, 2.0 * t), 0.1, alpha)


def model_cells(radio: RadioMap) -> list[Cell]:
    """The radio model's covered cells (none without a model): where it does not reach,
    the site shows through."""
    prediction = radio.prediction
    if prediction is None:
        return []
    grid = prediction.grid
    cells = []
    pairs = zip(prediction.signal, prediction.covered, strict=False)
    for index, (dbm, covered) in enumerate(pairs):
        if covered:
            x, y = grid.centre(index)
            cells.append(Cell(x, y, grid.resolution, signal_color(dbm, True, MODEL_ALPHA)))
    return cells


def measured_cells(radio: RadioMap, now: float) -> list[Cell]:
    """The robots' readings, the newest per cell; old ones fainter."""
    size = radio.resolution * 0.8
    cells = []
    for r in radio.readings():
        alpha = OLD_ALPHA if now - r.stamp > OLD_AFTER else MEASURED_ALPHA
        cells.append(Cell(r.x, r.y, size, signal_color(r.dbm, r.covered, alpha)))
    return cells


def last_links(
    radio: RadioMap, now: float, in_contact: frozenset[str] = frozenset()
) -> list[LastLink]:
    """Each robot's last position with a link, labelled ``<robot> last link: -72 dBm 26 s
    ago`` unless the robot is ``in_contact`` (its link is up): then it stands at its mark and
    its status line says so, and a label there would only cover that line."""
    return [
        LastLink(
            agent,
            reading.x,
            reading.y,
            "" if agent in in_contact else f"{agent} last link: {reading_text(reading, now)}",
            now - reading.stamp > OLD_AFTER,
        )
        for agent, reading in sorted(radio.last_link.items())
    ]
