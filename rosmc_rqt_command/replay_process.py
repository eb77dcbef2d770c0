"""The replay the command GUI starts itself: ``rosmc replay`` and the rviz marker node.

Both run as child processes on the GUI's ROS master, under one prefix (``/replay``): the
replay begins paused at the start and holds at the end (``--paused --hold``); the marker
node is the one ``roslaunch rosmc markers.launch ns:=/replay`` starts, so rviz started
with ``roslaunch rosmc rviz.launch ns:=/replay`` follows the same replay. They are ended
(SIGTERM, then SIGKILL) when the GUI returns to the live mission or closes, and get SIGTERM
from the kernel if the GUI dies (:mod:`.replay_child`).
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = "rosmc_rqt_command.replay_child"  # each child ends when this process does
GRACE = 5.0
"""Seconds a child gets to leave after SIGTERM before it is killed."""


class ReplayProcess:
    """One recording replayed under ``prefix`` by child processes; :meth:`stop` ends them.

    Args:
        path: The recording (.mcap).
        prefix: Where the replay publishes (``/replay``).
    """

    def __init__(self, path: str | Path, prefix: str) -> None:
        self.path = Path(path)
        self.prefix = prefix
        # The replay's stderr, kept while it runs (closed by stop()).
        self._log = tempfile.TemporaryFile(mode="w+", prefix="rosmc-replay-")  # noqa: SIM115
        self._children: list[subprocess.Popen[bytes]] = []

    def start(self) -> None:
        """Start the replay and the marker node (returns at once)."""
        replay = [str(self.path), "--prefix", self.prefix, "--paused", "--hold"]
        markers = [f"__ns:={self.prefix}/rosmc", f"_ns:={self.prefix}"]
        for kind, args in (("replay", replay), ("markers", markers)):
            self._children.append(
                subprocess.Popen(
                    [sys.executable, "-m", CHILD, str(os.getpid()), kind, *args],
                    stdin=subprocess.DEVNULL,
                    stdout=subprocess.DEVNULL,
                    stderr=self._log if kind == "replay" else subprocess.DEVNULL,
                    start_new_session=True,  # Ctrl-C in the GUI's terminal is the GUI's
                )
            )
        atexit.register(self.stop)

    @property
    def pids(self) -> list[int]:
        """The children's process ids (replay first)."""
        return [child.pid for child in self._children]

    def failure(self) -> str | None:
        """Why the replay left on its own (its last error line), or None while it runs."""
        if not self._children or self._children[0].poll() is None or self._log.closed:
            return None
        self._log.seek(0)
        lines = [line.strip() for line in self._log.read().splitlines() if line.strip()]
        return lines[-1] if lines else f"it ended with code {self._children[0].returncode}"

    def stop(self) -> None:
        """End both children (SIGTERM, then SIGKILL after a grace period)."""
        atexit.unregister(self.stop)
        for child in self._children:
            if child.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(child.pid, signal.SIGTERM)
        for child in self._children:
            try:
                child.wait(timeout=GRACE)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait()
        self._children = []
        self._log.close()
