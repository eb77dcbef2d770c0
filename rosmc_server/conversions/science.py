"""The science state (``rosmc/ScienceState``) <-> :class:`~.core.views.science.Science`."""

from __future__ import annotations

import rosmc.msg as wire

from ..core.views.science import RegionScience, Science


def science_from_msg(msg: wire.ScienceState) -> Science:
    """The score, the stones delivered and the discovered regions of a message."""
    regions = tuple(
        RegionScience(r.name, r.x, r.y, r.radius, r.max_score, int(r.stones_left), r.identified_by)
        for r in msg.regions
    )
    return Science(float(msg.score), int(msg.stones_delivered), regions)


def science_to_msg(science: Science) -> wire.ScienceState:
    """The message of ``science`` (no stamp, no event lines)."""
    return wire.ScienceState(
        regions=[
            wire.SampleRegion(
                name=r.name,
                x=r.x,
                y=r.y,
                radius=r.radius,
                max_score=r.max_score,
                stones_left=r.stones_left,
                identified_by=r.identified_by,
            )
            for r in science.regions
        ],
        score=science.score,
        stones_delivered=science.stones_delivered,
    )
