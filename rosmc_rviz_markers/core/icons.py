"""Status icons above each robot: what they say and in which colour.

Rows, top to bottom: the current skill and its status, the ground link, Wi-Fi, battery.
Every row is short camera-facing text in a colour that carries the threshold (green,
yellow, red), so the block is legible at the default zoom. No data is shown as such
("no telemetry"), never left out.
"""

from __future__ import annotations

from dataclasses import dataclass

from rosmc_server.core.agent_status import AgentStatus
from rosmc_server.core.model import SkillStatus

from .geometry import Color

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


@dataclass(frozen=True)
class IconRow:
    """One line of a robot's status block."""

    key: str
    text: str
    color: Color


def battery_row(level: float | None) -> IconRow:
    """Battery: a five-cell gauge and the percentage, red below 25 %, yellow below 50 %."""
    if level is None:
        return IconRow("battery", "BAT  no telemetry", DIM)
    level = min(max(level, 0.0), 1.0)
    cells = round(level * 5)
    gauge = "[" + "#" * cells + "." * (5 - cells) + "]"
    color = BAD if level < BATTERY_LOW else WARN if level < BATTERY_MID else GOOD
    return IconRow("battery", f"BAT {gauge} {level * 100:.0f}%", color)


def wifi_row(dbm: float | None) -> IconRow:
    """Wi-Fi: bars and dBm, red below -68 dBm, yellow below -60 dBm."""
    if dbm is None:
        return IconRow("wifi", "WIFI no telemetry", DIM)
    bars = 4 if dbm >= -55 else 3 if dbm >= WIFI_FAIR else 2 if dbm >= WIFI_WEAK else 1
    gauge = "|" * bars + "." * (4 - bars)
    color = BAD if dbm < WIFI_WEAK else WARN if dbm < WIFI_FAIR else GOOD
    return IconRow("wifi", f"WIFI {gauge} {dbm:.0f} dBm", color)


def link_row(link: str, last_heard: float) -> IconRow:
    """Ground link: up / down / never heard, with seconds since the robot was heard."""
    if link == "unknown" or last_heard < 0:
        return IconRow("link", "LINK never heard", DIM if link == "unknown" else BAD)
    ago = f"{last_heard:.0f} s ago" if last_heard >= 1 else "now"
    if link == "up":
        return IconRow("link", f"LINK up ({ago})", WARN if last_heard > LINK_STALE else GOOD)
    return IconRow("link", f"LINK DOWN ({ago})", BAD)


_STATUS_WORDS = {
    SkillStatus.RUNNING: (">", "running", GOOD),
    SkillStatus.SYNCWAITING: ("||", "waiting at barrier", WARN),
    SkillStatus.PAUSED: ("||", "paused", DIM),
    SkillStatus.FAILURE: ("X", "FAILED", BAD),
    SkillStatus.SUCCESS: ("OK", "done", Color(0.2, 0.9, 1.0)),
    SkillStatus.IDLE_SYNCHRONIZED: ("v", "uploaded, not started", NEUTRAL),
}


def skill_row(skill: str, status: SkillStatus | None, waiting_on: str = "") -> IconRow:
    """The robot's current skill and its status (waiting: on whom)."""
    if not skill or status is None or status is SkillStatus.IDLE:
        return IconRow("skill", "no skill synchronized", DIM)
    sign, words, color = _STATUS_WORDS[status]
    if status is SkillStatus.SYNCWAITING and waiting_on:
        words = f"waiting for {waiting_on}"
    return IconRow("skill", f"{sign} {skill}: {words}", color)


def status_rows(
    status: AgentStatus | None, skill_label: str = "", agent: str = ""
) -> tuple[IconRow, ...]:
    """The icon block of one robot, top row first (the robot's name before its skill).

    ``skill_label`` names the current skill as operators know it (its label); without it
    the skill id the robot reports is shown.
    """
    rows = _rows(status, skill_label)
    if not agent:
        return rows
    first = rows[0]
    return (IconRow(first.key, f"{agent}: {first.text}", first.color), *rows[1:])


def _rows(status: AgentStatus | None, skill_label: str) -> tuple[IconRow, ...]:
    if status is None:
        return (
            IconRow("skill", "no status yet", DIM),
            link_row("unknown", -1.0),
            wifi_row(None),
            battery_row(None),
        )
    return (
        skill_row(skill_label or status.current_skill, status.current_status, status.waiting_on),
        link_row(status.link, status.last_heard),
        wifi_row(status.wifi_signal),
        battery_row(status.battery),
    )
