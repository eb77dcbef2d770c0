"""Making this process a ROS node, for the tools that join the graph (CLI, GUIs, replay)."""

from __future__ import annotations

import os

import rospy


def init_node(name: str | None = None) -> str:
    """Make this process a ROS node (subscriptions need one); return its name.

    The default name is ``rosmc_cli_<pid>``. Signals stay with the caller (Ctrl-C
    raises KeyboardInterrupt as usual) and nothing is logged to ``/rosout``.
    Does nothing if the process is a node already.
    """
    if not rospy.core.is_initialized():
        rospy.init_node(
            name or f"rosmc_cli_{os.getpid()}",
            anonymous=False,
            disable_signals=True,
            disable_rosout=True,
        )
    return str(rospy.get_name())
