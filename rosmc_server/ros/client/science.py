"""What the science team (the simulator) publishes, for clients: the score and the regions.

Subscribes ``/rosmc/sim/science`` (rosmc/ScienceState, latched; behind a replay's prefix
when given).
"""

from __future__ import annotations

from collections.abc import Callable

import rosmc.msg as wire

from ... import interface
from ...conversions.science import science_from_msg
from ...core.views.science import Science
from .latched import LatchedWatch

SCIENCE_TYPE = "rosmc/ScienceState"


class ScienceWatch(LatchedWatch[Science]):
    """Follows the science state; ``on_science`` (if given) hears each one on a ROS thread.

    The process must be a ROS node already.
    """

    def __init__(
        self, prefix: str = "", on_science: Callable[[Science], None] | None = None
    ) -> None:
        topic = interface.prefixed(interface.SCIENCE_TOPIC, prefix)
        super().__init__(topic, wire.ScienceState, science_from_msg, on_science)
