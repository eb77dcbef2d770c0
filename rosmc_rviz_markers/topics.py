"""Every ROS name of the marker node, in one place (plain strings, no rospy).

All names are behind the node's ``ns`` prefix (``/replay`` for a replay view), like the
mission server's own names (:func:`rosmc_server.interface.prefixed`).
"""

from __future__ import annotations

from rosmc_server.interface import NAMESPACE, prefixed

NODE = f"{NAMESPACE}/markers"
# interactive_markers server topic namespace: <ns>/update, /update_full, /feedback.
MARKERS_NS = f"{NAMESPACE}/markers"
# visualization_msgs/MarkerArray, latched: status icons above every robot.
ICONS_TOPIC = f"{MARKERS_NS}/icons"
# visualization_msgs/MarkerArray, latched: the mission clock over the lander.
CLOCK_TOPIC = f"{MARKERS_NS}/clock"
# Stock rviz tools point here (rviz/operator.rviz):
NEW_POSITION_TOPIC = f"{MARKERS_NS}/new_position"  # geometry_msgs/PointStamped (Publish Point)
NEW_POSE_TOPIC = f"{MARKERS_NS}/new_pose"  # geometry_msgs/PoseStamped (2D Nav Goal)
NEW_AREA_TOPIC = (
    f"{MARKERS_NS}/new_area"  # geometry_msgs/PoseWithCovarianceStamped (2D Pose Estimate)
)

# Private parameters of the node (~name).
PARAM_NS = "ns"  # follow the mission under this prefix ("" live, "/replay" for a replay)
PARAM_READ_ONLY = "read_only"  # default: true when ns is set
PARAM_FOLLOW_TF = "follow_tf"  # agents follow TF (default: true when ns is empty)
PARAM_LIBRARY = "library"  # library file for a replay (the replay serves none)
PARAM_COMMIT_DELAY = "commit_delay"  # seconds of quiet after POSE_UPDATEs without MOUSE_UP


def topic(name: str, ns: str) -> str:
    """``name`` behind the node's ``ns`` prefix."""
    return prefixed(name, ns)
