"""The recording commands: replay, at, timeline, tobag and export.

All but ``replay`` read the journal file only and work without a ROS master.
Times are seconds since the recording started, as ``rosmc timeline`` draws them.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the commands import ROS late, so that --help stays fast
    from ..recording.history import MissionHistory
    from .context import Context

_Command = Callable[..., argparse.ArgumentParser]

REPLAY_HELP = """\
rviz, the command GUI and 'rosmc watch' then show the mission evolving.
Refuses to publish where a live mission server does, unless --prefix
moves the replay aside.

In a terminal: space pauses and resumes, left/right arrows seek 10 s back
and forth, [ and ] halve and double the rate, q quits; a progress line
shows time / duration, revision, rate and whether it is paused. Programs
steer it through the service <prefix>/rosmc/replay/control
(rosmc/ReplayControl) and follow it on <prefix>/rosmc/replay/state."""

AT_HELP = """\
WHEN is seconds since the recording started (12.5) or a revision (r42).
The mission shown is the one the mission server held then; a time past
the recording's end is refused, like a revision it does not hold."""

EXPORT_HELP = """\
OUT.mcap holds every recorded topic in chunks with indexes and a summary,
header stamps on the log clock, the robots drawn as markers in their TF
frames (/rosmc/export/robots), and the mission as text: the task panel at
every revision (/rosmc/export/tasks) and one line per change
(/rosmc/export/changes)."""


def add_commands(command: _Command) -> None:
    """Add the recording subcommands through the parser's ``command`` helper."""
    replay = command(
        "replay", "republish a recording onto the ROS graph (needs a ROS master)", REPLAY_HELP
    )
    replay.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    replay.add_argument(
        "--rate", type=_positive, default=1.0, metavar="R", help="speed-up (default 1: as recorded)"
    )
    replay.add_argument(
        "--start", type=_seconds, default=0.0, metavar="S", help="begin S seconds in (default 0)"
    )
    replay.add_argument(
        "--prefix",
        default="",
        metavar="P",
        help="put P before every name, e.g. /replay (default: the live names)",
    )
    replay.add_argument(
        "--hold",
        action="store_true",
        help="stay at the end until stopped (always so when keys steer it from a terminal)",
    )
    replay.add_argument(
        "--paused", action="store_true", help="begin paused (resume with space or the service)"
    )
    at = command("at", "print the mission as it was at a time or revision of a recording", AT_HELP)
    at.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    at.add_argument("when", metavar="WHEN", help="seconds since the start, or rN for revision N")
    at.add_argument("-v", "--verbose", action="store_true", help="show parameter values")
    timeline = command("timeline", "draw every robot's skill executions of a recording")
    timeline.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    timeline.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="OUT.svg, or OUT.png (ImageMagick)"
    )
    tobag = command("tobag", "convert a recording to a rosbag1 file for 'rosbag play'")
    tobag.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    tobag.add_argument("bag", metavar="OUT.bag", help="the bag to write")
    tobag.add_argument("-f", "--force", action="store_true", help="overwrite OUT.bag")
    export = command(
        "export",
        "write a recording as one indexed MCAP file for Foxglove and other MCAP tools",
        EXPORT_HELP,
    )
    export.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    export.add_argument("out", metavar="OUT.mcap", help="the file to write")
    export.add_argument("-f", "--force", action="store_true", help="overwrite OUT.mcap")


def replay(ctx: Context) -> int:
    """Republish the recording onto the graph, steered from the terminal or the service."""
    from ..recording import read_journal
    from ..recording.history import MissionHistory
    from ..ros.replayer import RecordingReplayer, ReplayConfig
    from .replay_session import ReplaySession
    from .terminal import is_terminal, keys_from

    args = ctx.args
    result = read_journal(args.file)
    history = _history(MissionHistory(result))
    keys = sys.stdin if not ctx.json and keys_from(sys.stdin) else None
    config = ReplayConfig(
        rate=args.rate,
        start=args.start,
        prefix=args.prefix,
        hold=args.hold or keys is not None,
        paused=args.paused,
    )
    session = ReplaySession(ctx.out, is_terminal(ctx.out), keys, progress=not ctx.json)
    player = RecordingReplayer(history, result.records, config, session.event)
    player.check_names()  # refuse before saying anything
    where = f"under {config.topic('')}" if config.topic("") else "on the live topic names"
    ctx.emit(
        f"replaying {history.path} ({history.duration:.1f} s, revisions "
        f"{history.revisions[0].revision} to {history.revisions[-1].revision}) from "
        f"{args.start:g} s at {args.rate:g}x {where}",
        None,
    )
    revision = session.run(player)
    ctx.emit(f"replay done at revision {revision}", {"revision": revision})
    return 0


def at(ctx: Context) -> int:
    """Print the mission at a time (seconds since the start) or a revision (rN)."""
    from ..recording.diff import resolve_when
    from ..recording.history import MissionHistory
    from ..recording.moments import review_histories
    from ..text import format_markers, format_tasks, mission_to_json
    from .context import UsageError

    when = ctx.args.when.strip()
    if not re.fullmatch(r"[rR]\d+", when):
        try:
            float(when)
        except ValueError:
            _history(MissionHistory.from_journal(ctx.args.file))
            raise UsageError(f"WHEN must be seconds or rN, got {when!r}") from None
    # Only the part files that hold the moment, when a long journal has several.
    history = _history(review_histories(ctx.args.file, [when])[0])
    moment = resolve_when(history, when)  # refuses a revision or time it does not hold
    state, when = moment.state, moment.label
    info = next(r for r in history.revisions if r.revision == state.revision)
    changed = history.seconds(info.log_time)
    last = f"{info.kind.name}: {info.summary}" if info.kind else "the recorded snapshot"
    title = f"{history.path.name} at {when}"
    text = format_tasks(state, title, verbose=ctx.args.verbose)
    text += f"\n  last change at {changed:.2f} s: {last}"
    if state.markers:
        markers = format_markers(state.markers).splitlines()
        text += "\n  task markers\n" + "\n".join(f"    {line}" for line in markers)
    data = mission_to_json(state)
    data["recording_time"] = changed
    data["summary"] = info.summary
    ctx.emit(text, data)
    return 0


def timeline(ctx: Context) -> int:
    """Draw the recording's per-robot timeline into an SVG or PNG file."""
    from ..core.views.vocabulary import counted
    from ..recording.overlays import timeline_with_overlays
    from ..recording.timeline_svg import write_timeline

    # With the operator's changes, link outages and the score drawn over the lanes.
    history, drawn = timeline_with_overlays(ctx.args.file)
    _history(history)
    title = (
        f"{history.path.name}: {history.duration:.1f} s, revision {history.revisions[-1].revision}"
    )
    path = write_timeline(drawn, ctx.args.output, title)
    runs = len(drawn.intervals)
    ctx.emit(
        f"wrote {path}: {counted(len(drawn.lanes), 'robot')}, {counted(runs, 'bar')}, "
        f"{counted(len(drawn.releases), 'barrier release')}",
        {"path": str(path), "robots": list(drawn.lanes), "bars": runs},
    )
    return 0


def tobag(ctx: Context) -> int:
    """Convert the recording to a rosbag1 file."""
    from ..recording.to_rosbag import journal_to_rosbag

    summary = journal_to_rosbag(ctx.args.file, ctx.args.bag, overwrite=ctx.args.force)
    if summary.skipped:
        print(f"rosmc: warning: {summary.skipped}", file=sys.stderr)
    counts = ", ".join(f"{topic} {count}" for topic, count in summary.counts.items())
    clock = "log time" if summary.clock == "log time" else f"the clock of {summary.clock} stamps"
    ctx.emit(
        f"wrote {summary.path}: {summary.total} messages ({counts}); bag time is {clock}",
        {"path": str(summary.path), "counts": summary.counts, "clock": summary.clock},
    )
    return 0


def export(ctx: Context) -> int:
    """Write the recording as one chunked, indexed MCAP file for Foxglove."""
    from ..recording.export import export_recording

    summary = export_recording(ctx.args.file, ctx.args.out, overwrite=ctx.args.force)
    if summary.skipped:
        print(f"rosmc: warning: {summary.skipped}", file=sys.stderr)
    ctx.emit(
        f"wrote {summary.path}: {summary.total} messages on {len(summary.counts)} topics",
        {"path": str(summary.path), "counts": dict(summary.counts)},
    )
    return 0


COMMANDS: dict[str, Callable[[Context], int]] = {
    "replay": replay,
    "at": at,
    "timeline": timeline,
    "tobag": tobag,
    "export": export,
}
"""The recording commands by name, for the dispatcher in :mod:`.main`."""


def _history(history: MissionHistory) -> MissionHistory:
    """Warn on stderr about revisions the recording lacks; return the history.

    (What reading the file found wrong is logged by the reader already.)
    """
    for line in history.problems:
        print(f"rosmc: warning: {line}", file=sys.stderr)
    return history


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def _seconds(text: str) -> float:
    value = float(text)
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"must be 0 or more seconds, got {text}")
    return value
