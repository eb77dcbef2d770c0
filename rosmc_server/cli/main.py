"""Entry point of ``rosmc``: parse, run one command, map failures to exit codes."""

from __future__ import annotations

import logging
import os
import sys
from collections.abc import Callable, Sequence

from .. import venv
from .parser import build_parser

EXIT_OK = 0
EXIT_REFUSED = 1
EXIT_USAGE = 2
EXIT_UNREACHABLE = 3
EXIT_INTERRUPTED = venv.EXIT_INTERRUPTED


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``rosmc`` with ``argv`` (default: the process arguments); return the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)  # exits 2 on usage errors, 0 after --help
    _quiet_ros_logging()
    try:
        # Imported late: rospy and the generated messages load slowly, and --help needs neither.
        from ..core import RosmcError
        from ..core.errors import ServerUnavailable
        from ..ros.client import MissionClient, identify
        from . import edits
        from .context import Context, UsageError
    except ImportError as error:
        return _fail(f"cannot load ROS or the rosmc messages ({error}); source env.sh", 1)
    if args.command in edits.COMMANDS:  # the operator allow-list knows a change by its node
        identify()
    client = MissionClient(timeout=args.timeout)
    try:
        return _command(args.command)(Context(args, client))
    except UsageError as error:
        return _fail(f"{error} (see 'rosmc {args.command} --help')", EXIT_USAGE)
    except ServerUnavailable as error:
        return _fail(str(error), EXIT_UNREACHABLE)
    except RosmcError as error:
        return _fail(str(error), EXIT_REFUSED)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader left (`rosmc watch | head`): stop quietly, also at interpreter exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    finally:
        client.close()


def _command(name: str) -> Callable[..., int]:
    from . import edits, keys, replay, review, views

    read_only: dict[str, Callable[..., int]] = {
        "status": views.status,
        "library": views.library,
        "markers": views.markers,
        "watch": views.watch,
    }
    recording = {**replay.COMMANDS, **review.COMMANDS, **keys.COMMANDS}
    return read_only.get(name) or recording.get(name) or edits.COMMANDS[name]


def _fail(message: str, code: int) -> int:
    print(f"rosmc: {message}", file=sys.stderr, flush=True)
    return code


def _quiet_ros_logging() -> None:
    # rospy warns on its own logger while it waits for a service; the CLI says it in one line.
    logging.getLogger("rosout").setLevel(logging.ERROR)
    logging.basicConfig(level=logging.WARNING, format="rosmc: %(message)s")
