"""The ``rosmc`` command line: every subcommand, its arguments and its help."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence

from ..core.skills.policy import DEFAULT_AFTER, LostLinkKind, LostLinkTrigger
from .keys import add_commands as _add_keys
from .replay import add_commands as _add_recording
from .review import add_commands as _add_review

DEFAULT_TIMEOUT = 5.0

# add_command(name, summary, epilog=None): a new subcommand parser.
_Command = Callable[..., argparse.ArgumentParser]

DESCRIPTION = """\
Scriptable client of the ROSMC mission server: inspect and edit the mission,
synchronize it to the robots and control their execution.

Exit codes: 0 success, 1 refused by the server (the reason on stderr),
2 usage error, 3 server not reachable within --timeout."""

PARAMS_HELP = """\
Parameters are key=value, read per the library schema: altitude=12,
target=3,4,0,0,0,1.57 (x,y[,z,roll,pitch,yaw]) or target='{x: 3, y: 4}',
area='[{x: 0, y: 0}, {x: 5, y: 0}, {x: 5, y: 5}]', mode=quick, flag=true.
key=@MARKER binds the parameter to a task marker (key=@ unbinds it in edit);
key=@@text is the text '@text'. See 'rosmc library' for every schema."""


POLICY_HELP = """\
continue keeps executing; hold pauses the robot after SECONDS without the
ground; safe_skill pauses it and runs --skill with each --param KEY=VALUE
(read as in 'rosmc add'), then holds; return_to_link runs --skill (one that
goes to a pose, e.g. navigate_to) to where the robot last had a link, then
holds. --when idle counts only the seconds the robot also has nothing left
to do. Until an operator chooses, a robot follows its library default. The
robot reports the policy in force ('rosmc status', "policy")."""


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, got {text}")
    return value


def _count(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text}")
    return value


def _revision(text: str) -> int:
    """A mission revision: 1 or more (no mission is at 0, which on the wire means no check)."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a mission revision (1 or more), got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``rosmc`` with all its subcommands."""
    parser = argparse.ArgumentParser(
        prog="rosmc",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--timeout",
        type=_positive,
        default=DEFAULT_TIMEOUT,
        metavar="SECONDS",
        help=f"how long to wait for the mission server (default {DEFAULT_TIMEOUT:g})",
    )
    parser.add_argument("--json", action="store_true", help="print machine-readable JSON")
    parser.add_argument(
        "--revision",
        type=_revision,
        metavar="N",
        help="make changes against mission revision N (1 or more): refused (exit 1) if the "
        "mission has changed since (default: the current mission)",
    )
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--json", action="store_true", default=argparse.SUPPRESS, help="print JSON")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    def command(
        name: str, summary: str, epilog: str | None = None, aliases: Sequence[str] = ()
    ) -> argparse.ArgumentParser:
        return sub.add_parser(
            name,
            aliases=list(aliases),
            help=summary,
            description=summary,
            epilog=epilog,
            parents=[common],
            formatter_class=argparse.RawDescriptionHelpFormatter,
        )

    _add_views(command)
    _add_editing(command)
    _add_execution(command)
    _add_markers(command, common)
    _add_files(command)
    _add_recording(command)
    _add_review(command)
    _add_keys(command)
    return parser


def _add_views(command: _Command) -> None:
    status = command("status", "print every robot's task, link and telemetry")
    status.add_argument("-v", "--verbose", action="store_true", help="show parameter values")
    status.add_argument(
        "--no-states",
        action="store_true",
        help="do not wait for the robots' link states or the science score",
    )
    library = command("library", "print the agents, their skills and parameter schemas")
    library.add_argument("agent", nargs="?", metavar="AGENT", help="only this agent")
    watch = command("watch", "print mission events as they happen (Ctrl-C stops)")
    watch.add_argument(
        "--states",
        type=_positive,
        nargs="?",
        const=5.0,
        metavar="SECONDS",
        help="also print the robots' states, at most every SECONDS (default 5)",
    )
    watch.add_argument("--count", type=_count, metavar="N", help="stop after N events")


def _add_editing(command: _Command) -> None:
    add = command("add", "add a skill to a robot's blueprint", PARAMS_HELP)
    add.add_argument("agent", metavar="ROBOT")
    add.add_argument("skill", metavar="SKILL")
    add.add_argument("params", nargs="*", metavar="KEY=VALUE", help="parameter values")
    add.add_argument("--label", default="", help="name shown to operators (default: SKILL)")
    add.add_argument(
        "--index", type=int, help="insert at this position of the task (default: append)"
    )
    _add_options(add)
    edit = command("edit", "change a blueprint skill", PARAMS_HELP)
    edit.add_argument("skill_id", metavar="ID")
    edit.add_argument("params", nargs="*", metavar="KEY=VALUE", help="parameters to change")
    edit.add_argument("--label", help="new label")
    _add_options(edit)
    delete = command("delete", "delete blueprint skills")
    delete.add_argument("skill_ids", nargs="+", metavar="ID")
    reorder = command("reorder", "give a robot's blueprint a new order")
    reorder.add_argument("agent", metavar="ROBOT")
    reorder.add_argument("order", nargs="+", metavar="ID", help="every blueprint skill, in order")
    barrier = command("barrier", "make skills on different robots start together")
    barrier.add_argument("skill_ids", nargs="+", metavar="ID")
    delete_barrier = command(
        "delete-barrier", "remove a barrier whose skills have not started", aliases=["unbarrier"]
    )
    delete_barrier.add_argument("barrier_id", metavar="BARRIER_ID")
    undo = command(
        "undo",
        "take back a blueprint, barrier or marker edit as a new revision",
        epilog="Without REVISION, the latest edit not undone yet; again and again, the ones "
        "before it. Give an undo's revision to redo what it undid. Refused once a skill it "
        "touches was sent to its robot, or when someone changed it since.",
    )
    undo.add_argument(
        "undo_revision",
        nargs="?",
        type=int,
        default=0,
        metavar="REVISION",
        help="the revision the edit produced",
    )


def _add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--timeout",
        dest="skill_timeout",
        type=float,
        metavar="SECONDS",
        help="the skill's execution timeout (0: none)",
    )
    parser.add_argument(
        "--retries", type=int, metavar="N", help="automatic retries on the robot after a failure"
    )


def _add_execution(command: _Command) -> None:
    sync = command("sync", "upload a robot's blueprint (or a prefix of it) to the robot")
    sync.add_argument("agent", metavar="ROBOT", nargs="?")
    sync.add_argument(
        "--upto",
        metavar="ID",
        action="append",
        help="upload up to and including this skill (with --all: once per robot that stops early)",
    )
    sync.add_argument(
        "--all",
        dest="team",
        action="store_true",
        help="every robot with planned skills, in one change: all of them or none",
    )
    unsync = command("unsync", "pull not-started synchronized skills back to the blueprint")
    unsync.add_argument("agent", metavar="ROBOT")
    unsync.add_argument(
        "--from", dest="from_id", metavar="ID", help="this skill and all after it (default: all)"
    )
    for name, summary in (
        ("start", "start executing synchronized skills on ROBOT (default: every robot)"),
        ("pause", "pause ROBOT's running skill (default: every robot)"),
        ("resume", "resume ROBOT's paused skill (default: every robot)"),
        ("stop", "stop ROBOT's running skill; it stays synchronized (default: every robot)"),
    ):
        control = command(name, summary)
        control.add_argument("agent", nargs="?", metavar="ROBOT")
    policy = command(
        "lost-link-policy",
        "set what a robot does when it stops hearing the ground station",
        POLICY_HELP,
    )
    policy.add_argument("agent", metavar="ROBOT")
    policy.add_argument("kind", choices=[kind.value for kind in LostLinkKind], metavar="POLICY",
                        help="continue, hold, safe_skill or return_to_link")  # fmt: skip
    policy.add_argument(
        "--param",
        dest="params",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a parameter value of the safe skill (repeatable)",
    )
    policy.add_argument(
        "--after",
        type=_positive,
        default=DEFAULT_AFTER,
        metavar="SECONDS",
        help=f"silence before the policy acts (default {DEFAULT_AFTER:g})",
    )
    policy.add_argument(
        "--skill", default="", metavar="SKILL", help="the skill (safe_skill, return_to_link)"
    )
    policy.add_argument(
        "--when",
        choices=[trigger.value for trigger in LostLinkTrigger],
        default=LostLinkTrigger.SILENT.value,
        help="silent: count every second without the ground (default); idle: only those "
        "with nothing left to do",
    )
    retry = command("retry", "run a failed skill again (a new attempt after it)")
    retry.add_argument("skill_id", metavar="ID")
    skip = command("skip", "skip a failed skill; the robot continues after it")
    skip.add_argument("skill_id", metavar="ID")


def _add_markers(command: _Command, common: argparse.ArgumentParser) -> None:
    command("markers", "list the task markers")
    marker = command("marker", "add, move, rename or delete a task marker")
    actions = marker.add_subparsers(dest="marker_command", metavar="ACTION", required=True)
    where_help = (
        "x,y[,z,roll,pitch,yaw] or '{x: 1, y: 2}'; an area: 'x,y x,y x,y ...' "
        "(put -- before a WHERE that starts with '-')"
    )
    add = actions.add_parser("add", help="add a task marker", parents=[common])
    add.add_argument("name", metavar="NAME", help="its name ('' for a generated one)")
    add.add_argument("type", choices=("position", "pose", "area"), metavar="TYPE",
                     help="position, pose or area")  # fmt: skip
    add.add_argument("where", metavar="WHERE", help=where_help)
    move = actions.add_parser("move", help="move a task marker", parents=[common])
    move.add_argument("name", metavar="NAME")
    move.add_argument("where", metavar="WHERE", help=where_help)
    rename = actions.add_parser("rename", help="rename a task marker", parents=[common])
    rename.add_argument("name", metavar="NAME")
    rename.add_argument("new_name", metavar="NEW_NAME")
    delete = actions.add_parser("delete", help="delete an unused task marker", parents=[common])
    delete.add_argument("name", metavar="NAME")


def _add_files(command: _Command) -> None:
    new = command("new", "start an empty mission (keeps the task markers)")
    new.add_argument("--drop-markers", action="store_true", help="delete the task markers too")
    save = command("save", "save the mission as YAML into a local file")
    save.add_argument("file", metavar="FILE", help="where to write ('-': standard output)")
    save.add_argument(
        "--on-server",
        action="store_true",
        help="write FILE on the server's host instead (relative to its ~mission_dir)",
    )
    load = command("load", "replace the mission with one saved before")
    load.add_argument("file", metavar="FILE", help="a saved mission ('-': standard input)")
    load.add_argument(
        "--on-server",
        action="store_true",
        help="read FILE on the server's host instead (relative to its ~mission_dir)",
    )
