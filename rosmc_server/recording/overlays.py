"""The timeline of ``rosmc timeline`` with what happened around the robots' work.

On top of the lanes of skill executions: the operator's changes (sync, unsync, edits)
as marks on the time axis, the link outages from the recorded agent states shaded on
their robot's lane, and the simulator's score over time.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..core import EventKind
from ..core.views.vocabulary import ROBOT_EVENTS as _ROBOT_EVENTS  # drawn in the lanes: not marks
from ..interface import SCIENCE_TOPIC
from .history import MissionHistory
from .reader import read_journal
from .summary import link_outages
from .timeline import OperatorMark, Timeline

_MARK_KIND = {EventKind.SYNC_REQUESTED: "sync", EventKind.UNSYNC_REQUESTED: "unsync"}


def timeline_with_overlays(path: str | Path) -> tuple[MissionHistory, Timeline]:
    """Read the journal at ``path`` once; its history and its timeline with every overlay."""
    result = read_journal(path)
    history = MissionHistory(result)
    timeline = history.timeline()
    end = history.duration
    marks = tuple(
        OperatorMark(
            history.seconds(info.log_time), _MARK_KIND.get(info.kind, "edit"), info.summary
        )
        for info in history.revisions
        if info.kind is not None and info.kind not in _ROBOT_EVENTS
    )
    outages = tuple(
        (o.agent, o.start, end if o.end is None else o.end) for o in link_outages(result, history)
    )
    score = tuple(
        (history.seconds(r.log_time), float(r.message.score))
        for r in result.records
        if r.topic == SCIENCE_TOPIC
    )
    return history, replace(timeline, marks=marks, outages=outages, score=score)
