"""The words, marks, colours and number formats every view of a mission shares.

The command GUI (:mod:`rosmc_rqt_command.presentation`), the status blocks in rviz
(:mod:`rosmc_rviz_markers.core.icons`) and the text of ``rosmc``
(:mod:`rosmc_server.text.plain`) say a skill's status, who made a change and a number the
same way: from here. The simulator and rviz paint each body in the colour of
:data:`PALETTE`. Plain Python: colours are ``#rrggbb`` strings or RGBA tuples (0..1).
Words are for a geologist, not a roboticist.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType

from ..model.changes import EventKind
from ..model.control import HoldCause
from ..model.model import SkillStatus

STATUS_WORDS: Mapping[SkillStatus, str] = MappingProxyType(
    {
        SkillStatus.IDLE: "planned",
        SkillStatus.IDLE_SYNCHRONIZED: "on robot",
        SkillStatus.SYNCWAITING: "waiting",
        SkillStatus.RUNNING: "running",
        SkillStatus.PAUSED: "paused",
        SkillStatus.SUCCESS: "done",
        SkillStatus.FAILURE: "failed",
    }
)
"""A status in one word or two."""

STATUS_MARKS: Mapping[SkillStatus, str] = MappingProxyType(
    {
        SkillStatus.IDLE: "  ",
        SkillStatus.IDLE_SYNCHRONIZED: "==",
        SkillStatus.SYNCWAITING: "..",
        SkillStatus.RUNNING: ">>",
        SkillStatus.PAUSED: "||",
        SkillStatus.SUCCESS: "ok",
        SkillStatus.FAILURE: "!!",
    }
)
"""A status in two characters, for terminals and one-line labels."""

# Planned work is plain white, work on the robot blue, work in progress green (amber while
# it waits for a partner), finished work fades to a warm grey, and a failure is a strong
# red: it must catch the eye. Light enough to be a table row's background under dark text
# and to be read as text on rviz's dark background.
STATUS_COLOURS: Mapping[SkillStatus, str] = MappingProxyType(
    {
        SkillStatus.IDLE: "#ffffff",
        SkillStatus.IDLE_SYNCHRONIZED: "#b4cff5",
        SkillStatus.SYNCWAITING: "#ffc94d",
        SkillStatus.RUNNING: "#6fcf7f",
        SkillStatus.PAUSED: "#b9a6d9",
        SkillStatus.SUCCESS: "#d9d6c6",
        SkillStatus.FAILURE: "#d7382b",
    }
)
"""The colour of a status (``#rrggbb``)."""

ROBOT_EVENTS = frozenset(
    {
        EventKind.SYNC_CONFIRMED,
        EventKind.SYNC_DECLINED,
        EventKind.UNSYNC_CONFIRMED,
        EventKind.STATUS_CHANGED,
    }
)
"""The changes the robots make (their answers and reports)."""

OPERATOR_EVENTS = frozenset(EventKind) - ROBOT_EVENTS
"""Every other change: something an operator did."""

Rgba = tuple[float, float, float, float]

PALETTE: Mapping[str, Rgba] = MappingProxyType(
    {
        "ground": (0.76, 0.45, 0.30, 1.0),
        "obstacles": (0.45, 0.30, 0.25, 1.0),
        "slopes": (0.60, 0.35, 0.20, 0.35),
        "lander": (0.85, 0.85, 0.88, 1.0),
        "drone": (0.20, 0.55, 0.95, 1.0),
        "science_rover": (0.95, 0.75, 0.20, 1.0),
        "manipulator_rover": (0.30, 0.80, 0.40, 1.0),
        "rover": (0.85, 0.55, 0.25, 1.0),
        "boxes": (0.80, 0.80, 0.80, 1.0),
        "robot": (0.70, 0.70, 0.70, 1.0),  # a body of no known kind
        "stones": (0.30, 0.30, 0.32, 1.0),
        "regions": (0.95, 0.85, 0.20, 0.35),
        "region_labels": (1.0, 1.0, 1.0, 1.0),
        "score": (1.0, 0.45, 0.85, 1.0),  # the science score over the lander: a colour of its own
        "wifi": (0.20, 0.60, 1.00, 0.8),
    }
)
"""One colour per body and layer of the world, for pybullet and rviz alike (RGBA, 0..1)."""


def rgb(colour: str) -> tuple[float, float, float]:
    """A ``#rrggbb`` colour as red, green and blue from 0 to 1."""
    return (int(colour[1:3], 16) / 255, int(colour[3:5], 16) / 255, int(colour[5:7], 16) / 255)


def number(value: float, decimals: int = 2) -> str:
    """A number for people: at most ``decimals`` decimals, no trailing zeros, never ``-0``."""
    if not math.isfinite(value):
        return str(value)
    text = f"{value:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def percent(fraction: float) -> str:
    """A fraction (0..1) as a whole percentage: ``97%``."""
    return f"{fraction * 100:.0f}%"


def dbm(signal: float) -> str:
    """A radio signal strength: ``-54 dBm``."""
    return f"{signal:.0f} dBm"


# Wi-Fi signal bands (dBm), as rviz colours them: yellow below the first, red below the second.
WIFI_FAIR_DBM = -60.0
WIFI_WEAK_DBM = -68.0


def wifi_words(signal: float, in_coverage: bool) -> str:
    """A Wi-Fi signal in an operator's words: good, fair, weak or out of range."""
    if not in_coverage:
        return "out of range"
    if signal >= WIFI_FAIR_DBM:
        return "good"
    return "fair" if signal >= WIFI_WEAK_DBM else "weak"


def counted(count: int, noun: str, plural: str = "") -> str:
    """A count and its noun, plural unless the count is one: ``1 skill``, ``0 stones``.

    ``plural`` is for nouns that do not just take an ``s``.
    """
    return f"{count} {noun if count == 1 else plural or noun + 's'}"


def age_text(seconds: float) -> str:
    """An age to the second, in the two largest units: ``45 s``, ``1 min 32 s``, ``2 h 5 min``."""
    whole = max(0, int(seconds))
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    if hours:
        return f"{hours} h {minutes} min"
    if minutes:
        return f"{minutes} min {secs} s"
    return f"{secs} s"


HOLD_WHERE: Mapping[HoldCause, str] = MappingProxyType(
    {
        HoldCause.NONE: "after its lost-link policy acted",
        HoldCause.LOST_LINK: "where it lost the link",
        HoldCause.RETURN_POINT: "at its lost-link return point",
        HoldCause.SAFE_SKILL: "after its lost-link safe skill",
    }
)
"""Where (and so why) a robot holds after its lost-link policy acted, for operators."""

HOLDING_LABEL = "holding \u2014 Resume from its menu"
"""What a holding robot's label in rviz says instead of its skill."""
