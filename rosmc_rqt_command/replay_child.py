"""A process of the command window's replay that ends when the window ends, however it ends.

``python -m rosmc_rqt_command.replay_child PARENT_PID replay|markers ARGS...`` asks the
kernel to send it SIGTERM when its parent dies (Linux ``PR_SET_PDEATHSIG``), then runs
``rosmc replay ARGS`` or the rviz marker node with ``ARGS``. A window that closes ends its
children itself (:meth:`ReplayProcess.stop`); this covers the window that crashes or is
killed with -9, which used to leave its replay and marker node running, and rviz following a
replay nobody could steer.
"""

from __future__ import annotations

import ctypes
import importlib
import os
import signal
import sys
from collections.abc import Callable, Sequence

PR_SET_PDEATHSIG = 1  # from <sys/prctl.h>
ENTRY_POINTS = {
    "replay": ("rosmc_server.cli", ["replay"]),
    "markers": ("rosmc_rviz_markers.ros.node", []),
}
"""What each kind of child runs: the module whose ``main()`` reads ``sys.argv``, and the
words before the caller's arguments."""


def end_with_parent(parent: int) -> bool:
    """Ask for SIGTERM when the parent dies; False if ``parent`` is no longer the parent.

    The check after the request closes the race of a parent that died before it: the
    child has then been handed to init (or a subreaper) already.
    """
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        prctl = None  # not Linux: the window's own stop() is all there is
    if prctl is not None and prctl(PR_SET_PDEATHSIG, signal.SIGTERM) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
    return os.getppid() == parent


def entry_point(kind: str) -> Callable[[], int | None]:
    """The ``main`` of the child ``kind`` (import it after setting ``sys.argv``: rospy
    reads the namespace and remappings from it when it is first imported)."""
    main: Callable[[], int | None] = importlib.import_module(ENTRY_POINTS[kind][0]).main
    return main


def main(argv: Sequence[str] | None = None) -> int:
    """Run one child of the window whose process id is the first argument."""
    parent, kind, *args = list(sys.argv[1:] if argv is None else argv)
    if kind not in ENTRY_POINTS:
        print(f"replay_child: unknown kind {kind!r}", file=sys.stderr)
        return 2
    if not end_with_parent(int(parent)):
        return 0  # the window is gone already
    sys.argv = [f"rosmc_{kind}", *ENTRY_POINTS[kind][1], *args]
    return int(entry_point(kind)() or 0)


if __name__ == "__main__":
    sys.exit(main())
