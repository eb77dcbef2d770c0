"""Radio coverage <-> messages: ``rosmc/CoverageGrid`` and ``rosmc/Telemetry`` readings."""

from __future__ import annotations

import rosmc.msg as wire

from ..core.robots.radio_map import GridSpec, Prediction, Reading


def prediction_from_msg(msg: wire.CoverageGrid) -> Prediction:
    """A ``rosmc/CoverageGrid`` as a :class:`Prediction`."""
    grid = GridSpec(msg.origin_x, msg.origin_y, msg.resolution, msg.width, msg.height)
    return Prediction(grid, tuple(msg.signal), tuple(bool(c) for c in bytes(msg.covered)))


def prediction_to_msg(prediction: Prediction, frame_id: str) -> wire.CoverageGrid:
    """A :class:`Prediction` as a ``rosmc/CoverageGrid`` (stamp left to the publisher)."""
    grid = prediction.grid
    return wire.CoverageGrid(
        frame_id=frame_id,
        origin_x=grid.origin_x,
        origin_y=grid.origin_y,
        resolution=grid.resolution,
        width=grid.width,
        height=grid.height,
        signal=list(prediction.signal),
        covered=bytes(1 if c else 0 for c in prediction.covered),
    )


def reading_from_telemetry(msg: wire.Telemetry) -> Reading:
    """What a ``rosmc/Telemetry`` says about the radio where the robot was."""
    return Reading(
        msg.agent,
        msg.pose.x,
        msg.pose.y,
        float(msg.wifi_signal),
        bool(msg.in_coverage),
        msg.stamp.to_sec(),
    )
