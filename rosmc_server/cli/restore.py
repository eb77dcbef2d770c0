"""``rosmc restore FILE --at T``: a past moment of a recording as the server's new blueprint.

The mission at T, without the skills that had ended, is loaded through the server's
load_mission service like ``rosmc load``. The server refuses while a robot holds
synchronized, unfinished work (the same rule as ``rosmc load`` and ``rosmc new``), and
there is deliberately no --force: replacing the mission under a robot that is executing
would orphan its skills. Stop a running skill and unsynchronize first.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .context import Context

_Command = Callable[..., argparse.ArgumentParser]


def add_command(command: _Command, when_help: str) -> None:
    """Add ``restore`` through the parser's ``command`` helper."""
    restore_parser = command(
        "restore",
        "load the mission as it was at a moment of a recording as a new blueprint",
        f"T is {when_help}.\n"
        "Skills that had ended (SUCCESS, FAILURE) are dropped; every other skill\n"
        "goes into its robot's blueprint as IDLE; barriers among the kept skills and\n"
        "all task markers are kept. Needs the mission server, which refuses while a\n"
        "robot holds synchronized, unfinished skills: unsynchronize or stop it first\n"
        "(there is no --force).",
    )
    restore_parser.add_argument("file", metavar="FILE", help="a mission journal (.mcap)")
    restore_parser.add_argument("--at", required=True, metavar="T", help="the moment to restore")


def restore(ctx: Context) -> int:
    """Load the recording's mission at ``--at`` into the running server as a blueprint."""
    import sys

    from ..core.files.persistence import dump_mission
    from ..core.views.vocabulary import counted
    from ..recording.diff import resolve_when
    from ..recording.moments import review_histories
    from ..recording.restore import blueprint_from

    history = review_histories(ctx.args.file, [ctx.args.at])[0]  # the parts that hold it
    for line in history.problems:
        print(f"rosmc: warning: {line}", file=sys.stderr)
    moment = resolve_when(history, ctx.args.at)
    restored = blueprint_from(moment.state)
    document = dump_mission(restored.content, moment.state.revision)
    result = ctx.client.load_mission(document, **ctx.against())
    text = (
        f"revision {result.revision}: restored {history.path.name} at {moment.label} "
        f"(r{moment.state.revision}) as a blueprint of {counted(restored.kept, 'skill')}"
    )
    if restored.dropped:
        text += f"; dropped {len(restored.dropped)} executed: {', '.join(restored.dropped)}"
    if restored.barriers_dropped:
        text += f"; dropped barriers {', '.join(restored.barriers_dropped)}"
    ctx.emit(
        text,
        {
            "revision": result.revision,
            "from_revision": moment.state.revision,
            "kept": restored.kept,
            "dropped": list(restored.dropped),
            "barriers_dropped": list(restored.barriers_dropped),
        },
    )
    return 0
