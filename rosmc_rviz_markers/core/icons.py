"""Status icons above each robot: what they say, in which colour, and at which height.

A robot's block is two short camera-facing lines, so that it stays above its own robot
without covering the others:

* the robot's name, its current skill and that skill's status
  (``science_rover: navigate_to >> running``), in the status's colour (the words, marks and
  colours of :mod:`rosmc_server.core.views.vocabulary`, as in the command GUI and ``rosmc``);
  a barrier wait says on whom and since how long; a robot holding after its lost-link
  policy says so and what frees it instead (``r4: holding — Resume from its menu``, red);
* its health: battery, Wi-Fi and ground link
  (``BAT 97% | WiFi -54 dBm | link up``), coloured by the worst of the three (green,
  yellow, red; the part past its threshold is written in capitals). Commands waiting
  for contact follow the link (``LINK DOWN 40 s, 2 WAITING 1 min``).

No data is shown as such (``?``, "never heard"), never left out. Robots whose blocks
would cover each other or a task marker's label from the shipped views (at the lander, at
one region, a row of robots) get their blocks lifted by whole blocks (:func:`icon_levels`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.model.model import SkillStatus
from rosmc_server.core.robots.agent_status import AgentStatus
from rosmc_server.core.robots.waiting import duration_text
from rosmc_server.core.views.geometry import Color, Point
from rosmc_server.core.views.vocabulary import (
    HOLDING_LABEL,
    STATUS_COLOURS,
    STATUS_MARKS,
    STATUS_WORDS,
    age_text,
    dbm,
    percent,
    rgb,
)

from .labels import LINE_SPACING, VIEW_PITCH, Box, Label

GOOD = Color(0.30, 1.00, 0.35)
WARN = Color(1.00, 0.85, 0.15)
BAD = Color(1.00, 0.30, 0.25)
NEUTRAL = Color(0.90, 0.90, 0.92)
DIM = Color(0.65, 0.65, 0.70)

BATTERY_LOW = 0.25  # below: red
BATTERY_MID = 0.5  # below: yellow
WIFI_WEAK = -68.0  # dBm, below: red
WIFI_FAIR = -60.0  # dBm, below: yellow
LINK_STALE = 5.0  # seconds since heard while up: yellow
SEPARATOR = " | "

# Where the block sits, in metres (the ROS layer turns rows into text markers). The rows
# are lines of one camera-facing text (each row's marker blanks the others' lines), so
# they stay apart on screen from every view; rows stacked in height would merge when seen
# from above.
# Above the robot's frame: the lower line's centre, clear of mast, arm and pin as the
# shipped views see them. Text faces the camera at full height while heights below it
# shrink by cos(pitch) on screen: at 2.15 m the lower line covered the drone's pin (what
# an operator clicks when the drone rests on the lander) from the first view (pitch 1.1).
ICON_BASE = 3.1
ICON_TEXT = 0.45  # letter height
ICON_ROW = ICON_TEXT * LINE_SPACING  # from one line's centre to the next, on screen
ICON_GAP = 0.2  # between two lifted blocks, as the view sees them
TYPICAL_LINE = 32  # characters in a health line (``BAT 97% | WiFi -54 dBm | link up``)

_SEVERITY = {GOOD: 0, NEUTRAL: 0, DIM: 1, WARN: 2, BAD: 3}


@dataclass(frozen=True)
class IconRow:
    """One line (or one part of a line) of a robot's status block."""

    key: str
    text: str
    color: Color


def battery_row(level: float | None) -> IconRow:
    """Battery: the percentage, red below 25 %, yellow below 50 %."""
    if level is None:
        return IconRow("battery", "BAT ?", DIM)
    level = min(max(level, 0.0), 1.0)
    color = BAD if level < BATTERY_LOW else WARN if level < BATTERY_MID else GOOD
    word = "BAT LOW" if color == BAD else "BAT"
    return IconRow("battery", f"{word} {percent(level)}", color)


def wifi_row(signal: float | None) -> IconRow:
    """Wi-Fi: the signal in dBm, red below -68 dBm, yellow below -60 dBm."""
    if signal is None:
        return IconRow("wifi", "WiFi ?", DIM)
    color = BAD if signal < WIFI_WEAK else WARN if signal < WIFI_FAIR else GOOD
    word = "WIFI WEAK" if color == BAD else "WiFi"
    return IconRow("wifi", f"{word} {dbm(signal)}", color)


def link_row(
    link: str, last_heard: float, waiting: int = 0, waiting_for: float = -1.0, forged: int = 0
) -> IconRow:
    """Ground link: up / down / never heard, with seconds since the robot was heard, how
    many commands wait for contact (for how long), and how many forged radio datagrams its
    link dropped; waiting work and forged datagrams are at least yellow."""
    row = _link_only(link, last_heard)
    if forged > 0:
        row = IconRow("link", f"{row.text}, {forged} FORGED DROPPED", worst([row.color, WARN]))
    if waiting <= 0 or link == "up":
        return row
    age = f" {duration_text(waiting_for)}" if waiting_for >= 0 else ""
    return IconRow("link", f"{row.text}, {waiting} WAITING{age}", worst([row.color, WARN]))


def _link_only(link: str, last_heard: float) -> IconRow:
    if link == "unknown" or last_heard < 0:
        return IconRow("link", "link never heard", DIM if link == "unknown" else BAD)
    if link == "up":
        if last_heard > LINK_STALE:
            return IconRow("link", f"link up, {last_heard:.0f} s ago", WARN)
        return IconRow("link", "link up", GOOD)
    return IconRow("link", f"LINK DOWN {last_heard:.0f} s", BAD)


def status_color(status: SkillStatus) -> Color:
    """The colour of a skill status, as in the command GUI (:data:`STATUS_COLOURS`)."""
    return Color(*rgb(STATUS_COLOURS[status]))


def skill_row(
    skill: str, status: SkillStatus | None, waiting_on: str = "", waited: float = -1.0
) -> IconRow:
    """The robot's current skill and its status (waiting: on whom, since how long); a
    failure in capitals."""
    if not skill or status is None or status is SkillStatus.IDLE:
        return IconRow("skill", "idle", NEUTRAL)
    word = STATUS_WORDS[status]
    if status is SkillStatus.SYNCWAITING and waiting_on:
        word = f"{word} on {waiting_on}"
    if status is SkillStatus.SYNCWAITING and waited >= 0:
        word = f"{word} since {age_text(waited)}"
    if status is SkillStatus.FAILURE:
        word = word.upper()
    return IconRow("skill", f"{skill} {STATUS_MARKS[status]} {word}", status_color(status))


def status_parts(status: AgentStatus | None, skill_label: str = "") -> tuple[IconRow, ...]:
    """Every part of a block: skill, link, Wi-Fi, battery (each with its own colour).

    ``skill_label`` names the current skill as operators know it (its label); without it
    the skill id the robot reports is shown.
    """
    if status is None:
        return (
            IconRow("skill", "no status yet", DIM),
            link_row("unknown", -1.0),
            wifi_row(None),
            battery_row(None),
        )
    if status.hold is not HoldCause.NONE:
        skill = IconRow("skill", HOLDING_LABEL, BAD)
    else:
        name = skill_label or status.current_skill
        skill = skill_row(name, status.current_status, status.waiting_on, status.barrier_wait)
    return (
        skill,
        link_row(
            status.link,
            status.last_heard,
            status.commands_waiting,
            status.waiting_for,
            status.radio_dropped,
        ),
        wifi_row(status.wifi_signal),
        battery_row(status.battery),
    )


def worst(colors: Sequence[Color]) -> Color:
    """The colour of the most severe part (red over yellow over grey over green)."""
    return max(colors, key=lambda c: _SEVERITY.get(c, 0))


def status_rows(
    status: AgentStatus | None, skill_label: str = "", agent: str = ""
) -> tuple[IconRow, IconRow]:
    """The two lines of one robot's block, top line first.

    ``skill``: ``<agent>: <skill> <status>`` in the status colour; ``health``:
    ``BAT .. | WiFi .. | link ..`` in the worst of their colours.
    """
    skill, link, wifi, battery = status_parts(status, skill_label)
    head = f"{agent}: {skill.text}" if agent else skill.text
    health = SEPARATOR.join(part.text for part in (battery, wifi, link))
    return (
        IconRow("skill", head, skill.color),
        IconRow("health", health, worst([battery.color, wifi.color, link.color])),
    )


def icon_levels(
    positions: Mapping[str, Point | None],
    lines: Mapping[str, Sequence[str]] | None = None,
    fixed: Iterable[Box] = (),
) -> dict[str, int]:
    """How many whole blocks to lift each robot's block (0 = right above the robot).

    Robots are taken from south to north (the shipped views look north, so a robot further
    north stands higher on screen and its block goes higher still); each gets the lowest
    level at which its block, as the shipped views see it (:mod:`.labels`), covers no
    block placed before and none of the ``fixed`` boxes (the task markers' labels, which
    stay put while robots drive by). ``lines`` are each block's texts (default: two lines
    of :data:`TYPICAL_LINE` characters). Robots without a known position come last, in the
    order given, and stack on each other as if together.
    """
    placed: list[Box] = list(fixed)
    unknown = 0
    out: dict[str, int] = {}
    order = sorted(positions.items(), key=lambda item: (item[1] is None, (item[1] or (0, 0))[1]))
    for agent, position in order:
        if position is None:
            out[agent], unknown = unknown, unknown + 1
            continue
        texts = tuple((lines or {}).get(agent, ("x" * TYPICAL_LINE,) * 2))
        box = _block(agent, position, 0, texts).box()
        # only boxes beside it can be in its way as it is lifted (a field of labels is big)
        beside = [b for b in placed if b.left < box.right and box.left < b.right]
        level = 0
        while hits := [other for other in beside if box.overlaps(other)]:
            # at least clear of the hit that ends lowest: no level in between can be free
            rise = min(hit.top for hit in hits) - box.bottom
            level += max(1, math.ceil(rise / _level_rise(len(texts)) - 1e-9))
            box = _block(agent, position, level, texts).box()
        out[agent] = level
        placed.append(box)
    return out


def _block(agent: str, position: Point, level: int, texts: Sequence[str]) -> Label:
    centre = position[2] + block_centre(level, len(texts))
    return Label(agent, position[0], position[1], centre, tuple(texts), ICON_TEXT, ICON_ROW)


def _level_rise(rows: int) -> float:
    """How far one level lifts a block on the view plane (see :func:`block_centre`)."""
    return ICON_ROW * (rows - 1) + ICON_TEXT + ICON_GAP


def block_centre(level: int, rows: int = 2) -> float:
    """Height (m above the robot's frame) of the centre of a block of ``rows`` at ``level``.

    One level lifts a block just enough to clear the one below it as the steepest shipped
    view sees it (looking down, height shows foreshortened by ``cos(pitch)``).
    """
    return ICON_BASE + ICON_ROW * (rows - 1) / 2 + level * _level_rise(rows) / math.cos(VIEW_PITCH)


def block_label(agent: str, position: Point, level: int, rows: Sequence[IconRow]) -> Label:
    """A robot's status block at ``level`` over map ``position``, as a label to keep clear of."""
    return _block(agent, position, level, [row.text for row in rows])
