"""The marker node's settings, and what its interaction layer needs of the node.

Both :mod:`.node` and :mod:`.interaction` import this module and neither imports the
other's module for types, so the two do not form an import circle.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import rospy

from rosmc_server.core.live.mirror import MissionMirror

from .. import topics
from ..core.scene import Scene, Touched
from ..core.specs import MarkerSpec


@dataclass(frozen=True)
class MarkerNodeConfig:
    """The node's settings (private parameters, read once)."""

    ns: str = ""
    read_only: bool = False
    follow_tf: bool = True
    library: str = ""
    commit_delay: float = 0.5

    @classmethod
    def from_params(cls) -> MarkerNodeConfig:
        """Read ``~ns``, ``~read_only``, ``~follow_tf``, ``~library``, ``~commit_delay``."""
        ns = str(rospy.get_param("~" + topics.PARAM_NS, "")).strip()
        return cls(
            ns=ns,
            read_only=bool(rospy.get_param("~" + topics.PARAM_READ_ONLY, bool(ns))),
            follow_tf=bool(rospy.get_param("~" + topics.PARAM_FOLLOW_TF, not ns)),
            library=str(rospy.get_param("~" + topics.PARAM_LIBRARY, "")),
            commit_delay=float(rospy.get_param("~" + topics.PARAM_COMMIT_DELAY, 0.5)),
        )


class MarkerHost(Protocol):
    """What the interaction layer reads of, and asks of, the marker node."""

    @property
    def mirror(self) -> MissionMirror:
        """The live mission copy."""

    @property
    def scene(self) -> Scene | None:
        """The scene (None until the library arrived)."""

    def published(self, name: str) -> MarkerSpec | None:
        """The spec last published under interactive marker ``name``."""

    def snap_back(self, name: str) -> None:
        """Publish marker ``name`` again as the mission has it."""

    def mark(self, touched: Touched) -> None:
        """Queue markers to refresh."""
