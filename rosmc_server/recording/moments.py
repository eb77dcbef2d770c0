"""One moment of a long journal, read from the part files that hold it.

A journal goes on in a new part file every few thousand changes, and each part opens
with a snapshot of the mission (:mod:`.writer`). ``rosmc at``, ``rosmc diff`` and
``rosmc restore`` ask for the mission at one or two moments; reading every part for
that costs the whole history. :func:`review_histories` instead reads each part's
opening snapshot (its revision and log time, from the file's first bytes, see
:mod:`._mcap.opening`), picks the part the moment falls in and reads that part alone
(the part before, for the revision a part opens with: the event that made it is there),
or with the part before when that alone cannot tell. The history of those parts gives
the same answer as the whole journal's: it starts from the same snapshot and applies
the same events, and time 0 is the journal's own (its first part's opening snapshot).

The opening snapshots are read without a CRC, so they only point the way; an answer is
taken from the parts only once it is verified: no damage, gap or problem in the parts
read, the moment found after their first revision (or in the first part), and a time
inside what they hold. Otherwise, and for a journal of one file, a journal whose part
numbers have holes, or a first part whose opening is unreadable, the whole journal is
read as before. What the answer cannot show is damage in a part it did not read.
"""

from __future__ import annotations

import bisect
import logging
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.core import RosmcError
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC, ROBOT_REPORTS_TOPIC
from rosmc_server.recording._mcap import scan as _scan
from rosmc_server.recording._mcap.files import journal_parts
from rosmc_server.recording._mcap.opening import Opening, opening_snapshot
from rosmc_server.recording.diff import parse_when, resolve_when
from rosmc_server.recording.errors import JournalError
from rosmc_server.recording.history import MissionHistory
from rosmc_server.recording.reader import decode_scan, join_results

__all__ = ["Segment", "review_histories", "segments"]

_log = logging.getLogger(__name__)

TOPICS = (MISSION_TOPIC, EVENTS_TOPIC, ROBOT_REPORTS_TOPIC)
"""What a history reads (as :meth:`MissionHistory.from_journal`)."""


@dataclass(frozen=True)
class Segment:
    """Consecutive part files that start the mission on their own: the first opens with
    a snapshot newer than the previous segment's; the others do not (a part started by
    a record other than a snapshot, or whose opening is unreadable)."""

    opening: Opening
    files: tuple[Path, ...]


def segments(path: str | Path) -> list[Segment] | None:
    """The segments of the journal at ``path``, oldest first; None if its parts cannot be
    told apart this way (one file, a part missing, the first part's opening unreadable)."""
    _, parts = journal_parts(path)
    numbers = [number for number, _ in parts]
    if len(parts) < 2 or numbers != list(range(1, len(parts) + 1)):
        return None
    found: list[Segment] = []
    for _, file in parts:
        opening = opening_snapshot(file)
        if not found:
            if opening is None:
                return None
            found.append(Segment(opening, (file,)))
            continue
        last = found[-1].opening
        if opening is None or opening.revision <= last.revision or opening.log_time < last.log_time:
            found[-1] = Segment(last, (*found[-1].files, file))
        else:
            found.append(Segment(opening, (file,)))
    return found


def review_histories(path: str | Path, moments: Sequence[str]) -> list[MissionHistory]:
    """For each of ``moments`` (see :data:`~.diff.WHEN_HELP`), a history that resolves it
    as the whole journal's history does (:func:`~.diff.resolve_when`): read from the
    parts that hold it when that can be verified, else the whole journal (read once).

    Raises:
        JournalError: The journal cannot be read (from reading it whole).
    """
    whole: MissionHistory | None = None
    found = segments(path)
    histories: list[MissionHistory] = []
    for text in moments:
        history = None if found is None else _from_parts(path, found, text)
        if history is None:
            if whole is None:
                whole = MissionHistory.from_journal(path)
            history = whole
        histories.append(history)
    return histories


def _from_parts(path: str | Path, found: list[Segment], text: str) -> MissionHistory | None:
    """A history of the segments ``text`` falls in, verified to resolve it as the whole
    journal would; None if that cannot be told."""
    start = found[0].opening.log_time
    try:
        target = parse_when(text, start)
    except RosmcError:
        return None  # the whole journal's history says what is wrong with it
    if target.revision is not None:
        keys = [segment.opening.revision for segment in found]
        at = bisect.bisect_right(keys, target.revision) - 1
    else:
        keys = [segment.opening.log_time for segment in found]
        at = bisect.bisect_right(keys, start + round(target.seconds * 1e9)) - 1
    at = max(at, 0)
    # The segment alone, then with the one before. A revision that opens a segment was
    # made by the last event of the one before: that one alone holds it, event and all.
    tries = [(at, at), (at - 1, at)]
    if target.revision is not None and target.revision == keys[at]:
        tries = [(at - 1, at - 1), (at - 1, at)]
    for first, last in tries:
        if first < 0:
            break
        history = _read(path, found[first : last + 1], start)
        if history is not None and _verified(history, text, first == 0, last == len(found) - 1):
            return history
    return None


def _read(path: str | Path, chosen: Sequence[Segment], start: int) -> MissionHistory | None:
    """The history of the files of ``chosen`` with time 0 at ``start``; None if they hold
    a record from before ``start`` (a clock set back) or cannot be read."""
    base, _ = journal_parts(path)
    try:
        results = [
            decode_scan(_scan.scan(file), TOPICS) for segment in chosen for file in segment.files
        ]
        result = join_results(base, results)
        if not result.records or min(record.log_time for record in result.records) < start:
            return None
        return MissionHistory(result, start)
    except JournalError as err:
        _log.debug("journal %s: reading it whole (%s)", base, err)
        return None


def _verified(history: MissionHistory, text: str, from_first: bool, to_last: bool) -> bool:
    """Whether ``history`` (of some segments) resolves ``text`` as the whole journal's would.

    Args:
        from_first: The segments read begin with the journal's first.
        to_last: They end with its last (the history's end is the journal's).
    """
    if history.damage or history.gaps or history.problems:
        return False
    revisions = history.revisions
    target = parse_when(text, history.start)
    if target.revision is not None:
        # The first revision read restarts from its snapshot: its event (kind, summary,
        # time) is in the part before, unless there is none.
        held = {info.revision for info in revisions}
        if target.revision not in held or (
            not from_first and target.revision <= revisions[0].revision
        ):
            return False
    else:
        log_time = history.start + round(target.seconds * 1e9)
        if target.seconds < 0 or (not to_last and log_time > history.end):
            return False
        if not from_first and (len(revisions) < 2 or log_time < revisions[1].log_time):
            return False
    try:
        resolve_when(history, text)
    except (RosmcError, JournalError):
        return False
    return not history.problems  # an event found not to apply on the way
