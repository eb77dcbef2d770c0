"""How skills, robots and parameters read in the GUI: words, short summaries and colours.

Plain Python (colours are ``#rrggbb`` strings), shared by the models and widgets so a
status looks the same everywhere. Words are for a geologist, not a roboticist.
"""

from __future__ import annotations

from rosmc_server.core import (
    AgentStatus,
    Pose,
    Resolution,
    SkillInstance,
    SkillStatus,
    Transfer,
    Value,
)
from rosmc_server.core.robots.link import LinkStatus
from rosmc_server.core.robots.waiting import duration_text
from rosmc_server.core.views.vocabulary import STATUS_COLOURS as STATUS_COLOURS
from rosmc_server.core.views.vocabulary import STATUS_WORDS as STATUS_WORDS
from rosmc_server.core.views.vocabulary import dbm, number, percent, rgb, wifi_words

TRANSFER_COLOUR = "#dae6fa"  # uploading or removing: on its way, not settled (italic too)
SETTLED_FAILURE_COLOUR = "#f9bbb0"  # a failure the operator retried or skipped
TEXT_COLOUR = "#1d1d1d"
DONE_TEXT_COLOUR = "#55524c"  # finished work reads as the past
ALARM_TEXT_COLOUR = "#ffffff"  # on the failure red
LAST_KNOWN_TEXT_COLOUR = "#5c5c5c"  # a robot out of contact: what it last said, greyed
# Barrier tags: saturated colours that stay apart from the status colours.
BARRIER_COLOURS = (
    "#7b3fa0",
    "#d35400",
    "#1f6fb2",
    "#b0264a",
    "#0e8c7a",
    "#8a6d00",
    "#5d4037",
    "#c2185b",
)


def row_colour(skill: SkillInstance) -> str:
    """The background of a skill's row."""
    if skill.transfer is not Transfer.NONE:
        return TRANSFER_COLOUR
    if skill.status is SkillStatus.FAILURE and skill.resolution is not Resolution.NONE:
        return SETTLED_FAILURE_COLOUR
    return STATUS_COLOURS[skill.status]


def text_colour(skill: SkillInstance) -> str:
    """The text colour of a skill's row (readable on :func:`row_colour`)."""
    if skill.transfer is not Transfer.NONE:
        return TEXT_COLOUR
    if skill.status is SkillStatus.FAILURE and skill.resolution is Resolution.NONE:
        return ALARM_TEXT_COLOUR
    if skill.is_settled:
        return DONE_TEXT_COLOUR
    return TEXT_COLOUR


def barrier_colour(number: int) -> str:
    """The shared colour of barrier number ``number`` (from 1)."""
    return BARRIER_COLOURS[(number - 1) % len(BARRIER_COLOURS)]


def status_text(
    skill: SkillInstance,
    waiting_on: list[str] | None = None,
    out_of_contact: bool = False,
    heard_ago: float = -1.0,
    holding: bool = False,
) -> str:
    """The status cell: a word, and what matters about it (pending transfer, wait, reason).

    ``out_of_contact``: the robot cannot be heard, so a transfer waits for contact, and
    what the robot last said of an unfinished skill may be old: it is marked last known,
    with how long ago the robot was heard (``heard_ago`` seconds; negative: never).
    ``holding``: the robot holds after its lost-link policy; its paused skill says so.
    """
    if skill.transfer is Transfer.UPLOADING and out_of_contact:
        return "waiting for contact"
    if skill.transfer is Transfer.REMOVING and out_of_contact:
        return "take-back waiting for contact"
    if skill.transfer is Transfer.UPLOADING:
        return "uploading…"
    if skill.transfer is Transfer.REMOVING:
        return "removing…"
    word = STATUS_WORDS[skill.status]
    if skill.status is SkillStatus.SYNCWAITING and waiting_on:
        word = f"waiting on {', '.join(waiting_on)}"
    if skill.status is SkillStatus.PAUSED and holding:
        word = "holding (Resume frees it)"
    if skill.status is SkillStatus.FAILURE and skill.resolution is not Resolution.NONE:
        word += f" ({skill.resolution.name.lower()})"
    if skill.attempt > 1:
        word += f", try {skill.attempt}"
    if is_last_known(skill, out_of_contact):
        word += (
            f" (last known, {duration_text(heard_ago)} ago)"
            if heard_ago >= 0
            else (" (last known)")
        )
    return word


def last_known_colour(colour: str) -> str:
    """``colour`` greyed: the row of a robot out of contact shows the past, not the present."""
    mixed = (round((part * 255 + 0xC8) / 2) for part in rgb(colour))
    return "#" + "".join(f"{part:02x}" for part in mixed)


def is_last_known(skill: SkillInstance, out_of_contact: bool) -> bool:
    """The row shows what an unheard robot last said of a skill that may have moved on."""
    return (
        out_of_contact
        and skill.transfer is Transfer.NONE
        and skill.status is not SkillStatus.IDLE
        and not skill.status.is_final
    )


def value_summary(value: Value) -> str:
    """A parameter value in a few characters."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return number(value)
    if isinstance(value, Pose):
        return f"({number(value.x)}, {number(value.y)})"
    if isinstance(value, list):
        return f"{len(value)} items" if len(value) != 1 else "1 item"
    if isinstance(value, dict):
        return f"{len(value)} keys" if len(value) != 1 else "1 key"
    return str(value) if value != "" else "–"


def params_summary(skill: SkillInstance, limit: int = 3) -> str:
    """The key parameters of a skill: bound markers first, then the first few values."""
    parts = [f"@{marker}" for marker in skill.bindings.values()]
    for name, value in skill.params.items():
        if name not in skill.bindings:
            parts.append(f"{name} {value_summary(value)}")
    return ", ".join(parts[:limit]) + (", …" if len(parts) > limit else "")


def link_summary(status: AgentStatus | None) -> str:
    """A robot's header line: link, seconds since heard, battery, Wi-Fi, policy."""
    if status is None or status.link is LinkStatus.UNKNOWN:
        waiting = status.waiting_text if status is not None else ""
        return f"never heard · {waiting}" if waiting else "never heard"
    link = "link up" if status.link is LinkStatus.UP else "LINK DOWN"
    if status.last_heard >= 0 and (status.link is not LinkStatus.UP or status.last_heard >= 2):
        link += f", heard {status.last_heard:.0f} s ago"
    parts = [link]
    if status.commands_waiting:
        parts.append(status.waiting_text)
    if status.battery is not None:
        parts.append(f"battery {percent(status.battery)}")
    if status.wifi_signal is not None:
        parts.append(f"Wi-Fi {wifi_words(status.wifi_signal, status.in_coverage)}")
    if status.executor_state:
        parts.append(status.executor_state)
    if status.policy:
        parts.append(status.policy)
    if status.radio_dropped:
        parts.append(status.radio_text)
    return " · ".join(parts)


def link_details(status: AgentStatus | None) -> str:
    """The numbers behind a robot's header, for its tooltip (signal, round trip)."""
    if status is None:
        return ""
    parts = []
    if status.wifi_signal is not None:
        parts.append(f"Wi-Fi signal {dbm(status.wifi_signal)}")
    if status.round_trip >= 0:
        parts.append(f"round trip {status.round_trip * 1000:.0f} ms")
    return ", ".join(parts)


def is_alarm(skill: SkillInstance) -> bool:
    """The skill needs the operator: an unresolved failure."""
    return skill.status is SkillStatus.FAILURE and skill.resolution is Resolution.NONE
