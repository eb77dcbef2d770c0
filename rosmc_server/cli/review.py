"""Reviewing a recording: ``rosmc info FILE`` (reads the file only; no ROS master needed)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
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


def info(ctx: Context) -> int:
    """Print what a recording holds."""
    import sys

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
        lines.append(f"  {robot.agent:<20} {', '.join(parts) or 'no skills'}")
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


COMMANDS: dict[str, Callable[[Context], int]] = {"info": info}
"""The review commands by name, for the dispatcher in :mod:`.main`."""
