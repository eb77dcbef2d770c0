"""What a node started by roslaunch needs to behave as the user expects: paths and restarts.

roslaunch starts every node in ``ROS_HOME`` (``~/.ros``), so a relative path the user typed
(``journal:=bags/m.mcap``) would land there. The launch files pass the directory the user
typed the command in as ``~cwd`` (``$(optenv PWD)``), and :func:`launch_path` resolves
relative paths against it; a node started by hand (``rosrun``) has no ``~cwd`` and resolves
against its own working directory, which is the user's.

A mission server that roslaunch restarts (``respawn``) goes on with the journal its
predecessor in the same launch was writing: the launch file sets ``~station_journal`` to
""; the server writes there the journal it opens (:func:`remember_journal`), and a server
that starts and finds a journal there resumes it (:func:`previous_journal`). roslaunch sets
parameters once per launch, not per respawn, so a new launch starts a new journal.

Parameters (private, of the node that calls these functions):
    ``~cwd`` (str): the directory relative paths are resolved against ("" = the node's own).
    ``~station_journal`` (str): the journal this launch's server writes (mission server only).
"""

from __future__ import annotations

import logging
from pathlib import Path

import rospy

_log = logging.getLogger(__name__)

CWD_PARAM = "~cwd"
STATION_JOURNAL_PARAM = "~station_journal"


def resolve_against(path: str | Path, cwd: str | Path) -> Path:
    """``path`` with ``~`` expanded, made absolute against ``cwd`` when relative ("" = as is)."""
    expanded = Path(path).expanduser()
    if expanded.is_absolute() or not str(cwd):
        return expanded
    return Path(cwd).expanduser() / expanded


def launch_path(path: str | Path) -> Path:
    """``path`` resolved against the directory the user launched from (``~cwd``)."""
    return resolve_against(path, str(rospy.get_param(CWD_PARAM, "")))


def previous_journal() -> Path | None:
    """The journal a server of this launch was writing when it ended, if there is one.

    None when the node was not started by a launch file that keeps the station's journal,
    when this is the launch's first server, or when its journal was never written.
    """
    written = str(rospy.get_param(STATION_JOURNAL_PARAM, ""))
    if not written:
        return None
    path = Path(written)
    if not path.exists():
        _log.warning("the previous server's journal %s is gone; starting a new one", path)
        return None
    return path


def remember_journal(path: Path) -> None:
    """Note the journal now written, for the server that roslaunch may start after this one."""
    if rospy.has_param(STATION_JOURNAL_PARAM):
        rospy.set_param(STATION_JOURNAL_PARAM, str(path.resolve()))
