"""Which node sent a message or made a service request.

rospy keeps the sender's caller id (its node name, e.g. ``/rosmc/sim``) in the connection
header it attaches to every received message and service request. ROS 1 does not check it:
a node can claim any name.
"""

from __future__ import annotations


def caller_id(received: object) -> str:
    """The node name that sent ``received`` ("" if rospy did not say)."""
    header = getattr(received, "_connection_header", None) or {}
    return str(header.get("callerid", ""))
