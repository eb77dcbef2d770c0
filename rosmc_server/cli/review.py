"""Reviewing a recording: ``rosmc info FILE`` and ``rosmc diff FILE T1 T2`` (read the file
only; no ROS master needed), and ``rosmc restore FILE --at T`` (see :mod:`.restore`)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from .restore import add_command as _add_restore
from .restore import restore as _restore_command

if TYPE_CHECKING:
    from ..recording.diff import FieldChange, MissionDiff
    from ..recording.summary import RecordingSummary
    from .context import Context

_Command = Callable[..., argparse.ArgumentParser]


def add_commands(command: _Command) -> None:
    """Add the review subcommands through the parser's ``command`` helper."""
    info = command(
        "info",
        "summarize a recording: duration, robots, changes, outcomes, outages, score",
        "Reads the journal only. --json gives the same as data for scripts.",
    )
    info.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    from ..recording.diff import WHEN_HELP  # pure Python, no ROS: --help stays fast

    diff = command(
        "diff",
        "what changed in a recording between two times or revisions",
        f"T1 and T2 are each {WHEN_HELP}.\nSkills added, removed and edited (parameter by "
        "parameter), status changes, barriers and task markers. --json for scripts.",
    )
    diff.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    diff.add_argument("first", metavar="T1", help="the earlier moment")
    diff.add_argument("second", metavar="T2", help="the later moment")
    _add_restore(command, WHEN_HELP)


def info(ctx: Context) -> int:
    """Print what a recording holds."""
    from ..recording.summary import summarize

    summary = summarize(ctx.args.file)
    for line in summary.problems:
        print(f"rosmc: warning: {line}", file=sys.stderr)
    ctx.emit(format_summary(summary), summary_data(summary))
    return 0


def format_summary(summary: RecordingSummary) -> str:
    """The summary as the text ``rosmc info`` prints."""
    lines = [
        f"{summary.path.name}: {_duration(summary.duration)}, {summary.size_bytes / 1024:.0f} kB, "
        f"revisions {summary.first_revision}..{summary.last_revision}",
        "robots (how their skills ended)",
    ]
    for robot in summary.robots:
        parts = [
            f"{getattr(robot, name)} {name}"
            for name in ("succeeded", "failed", "retried", "skipped", "unfinished", "blueprint")
            if getattr(robot, name)
        ]
        tried = f" ({robot.attempts} attempts)" if robot.attempts else ""
        lines.append(f"  {robot.agent:<20} {', '.join(parts) or 'no skills'}{tried}")
    total = sum(summary.changes.values())
    lines.append(f"changes ({total})")
    lines.append("  " + ", ".join(f"{kind} {n}" for kind, n in summary.changes.items()))
    if AGENT_STATES in summary.records:
        lines.append(f"link outages ({len(summary.outages)})")
        for outage in summary.outages:
            end = "end" if outage.end is None else f"{outage.end:.1f} s"
            length = outage.length(summary.duration)
            lines.append(f"  {outage.agent:<20} {outage.start:.1f} s to {end} ({length:.1f} s)")
    else:
        lines.append("link outages: no agent states recorded")
    if summary.final_score is None:
        lines.append("score: not recorded (no simulator science state)")
    else:
        lines.append(f"score {summary.final_score:.2f} at the end ({len(summary.score)} records)")
    lines.append("records: " + ", ".join(f"{t} {n}" for t, n in sorted(summary.records.items())))
    return "\n".join(lines)


def summary_data(summary: RecordingSummary) -> dict[str, Any]:
    """The summary as JSON-ready data (``rosmc --json info``)."""
    return {
        "path": str(summary.path),
        "size_bytes": summary.size_bytes,
        "duration_s": round(summary.duration, 3),
        "revisions": [summary.first_revision, summary.last_revision],
        "changes": summary.changes,
        "robots": [vars(robot) for robot in summary.robots],
        "outages": [
            {"agent": o.agent, "start_s": round(o.start, 3), "end_s": o.end}
            for o in summary.outages
        ],
        "final_score": summary.final_score,
        "score": [[round(t, 3), s] for t, s in summary.score],
        "records": summary.records,
        "problems": list(summary.problems),
    }


AGENT_STATES = "/rosmc/agent_states"


def _duration(seconds: float) -> str:
    minutes, rest = divmod(seconds, 60.0)
    return f"{int(minutes)} min {rest:.0f} s" if minutes else f"{rest:.1f} s"


def diff(ctx: Context) -> int:
    """Print what changed between two moments of a recording."""
    from ..recording.diff import diff_missions, resolve_when
    from ..recording.moments import review_histories

    moments = (ctx.args.first, ctx.args.second)
    histories = review_histories(ctx.args.file, moments)  # the parts that hold each moment
    for line in dict.fromkeys(line for history in histories for line in history.problems):
        print(f"rosmc: warning: {line}", file=sys.stderr)
    before, after = (resolve_when(h, t) for h, t in zip(histories, moments, strict=True))
    changes = diff_missions(before, after)
    ctx.emit(format_diff(changes), diff_data(changes))
    return 0


def format_diff(changes: MissionDiff) -> str:
    """The difference as the text ``rosmc diff`` prints."""
    before, after = changes.before, changes.after
    lines = [
        f"{before.label} (r{before.state.revision}, {before.seconds:.1f} s) -> "
        f"{after.label} (r{after.state.revision}, {after.seconds:.1f} s)"
    ]
    if changes.is_empty:
        return lines[0] + "\n  no changes"
    sections: list[tuple[str, Sequence[str]]] = [
        ("skills added", changes.skills_added),
        ("skills removed", changes.skills_removed),
        ("skills edited", [_change_text(c) for c in changes.edits]),
        ("status changes", [_change_text(c) for c in changes.statuses]),
        ("barriers added", changes.barriers_added),
        ("barriers removed", changes.barriers_removed),
        ("markers added", changes.markers_added),
        ("markers removed", changes.markers_removed),
        ("markers changed", [_change_text(c) for c in changes.marker_changes]),
    ]
    for title, entries in sections:
        if entries:
            lines.append(f"{title} ({len(entries)})")
            lines += [f"  {entry}" for entry in entries]
    return "\n".join(lines)


def diff_data(changes: MissionDiff) -> dict[str, Any]:
    """The difference as JSON-ready data (``rosmc --json diff``)."""
    data: dict[str, Any] = {
        side: {"label": m.label, "revision": m.state.revision, "seconds": round(m.seconds, 3)}
        for side, m in (("from", changes.before), ("to", changes.after))
    }
    for name in changes.__dataclass_fields__:
        value = getattr(changes, name)
        if name not in ("before", "after"):
            data[name] = [vars(v) if hasattr(v, "subject") else v for v in value]
    return data


def _change_text(change: FieldChange) -> str:
    return f"{change.subject} {change.field}: {change.before} -> {change.after}"


COMMANDS: dict[str, Callable[[Context], int]] = {
    "info": info,
    "diff": diff,
    "restore": _restore_command,
}
"""The review commands by name, for the dispatcher in :mod:`.main`."""
