"""The ROS side of steering a replay: its control service and its latched state.

Serves (behind the replay's prefix):
    ``/rosmc/replay/control`` (rosmc/ReplayControl): pause, resume, seek, set the rate, or
    only ask; the answer carries the replay's state after the call.

Publishes (behind the replay's prefix):
    ``/rosmc/replay/state`` (rosmc/ReplayState, latched): where the replay is, whenever it
    pauses, resumes, seeks, changes its rate or reaches the end.

The replay itself (:class:`~rosmc_server.ros.replayer.RecordingReplayer`) does the steering;
this module turns requests into its calls and its status into messages.
"""

from __future__ import annotations

import logging
import time
from typing import Any, Protocol

import rosmc.msg as wire
import rosmc.srv as wire_srv
import rospy

from .. import interface
from ..core import InvalidRequest, RosmcError
from ..recording.playback import PlaybackStatus

_log = logging.getLogger(__name__)

Request = wire_srv.ReplayControlRequest


class Steerable(Protocol):
    """What the control service steers (a running replay)."""

    def status(self) -> PlaybackStatus:
        """Where the replay is."""

    def pause(self) -> PlaybackStatus:
        """Stop where it is."""

    def resume(self) -> PlaybackStatus:
        """Go on (from the start, at the end)."""

    def seek(self, seconds: float, *, relative: bool = False) -> PlaybackStatus:
        """Move; the answer comes once subscribers have the state there."""

    def set_rate(self, rate: float) -> PlaybackStatus:
        """Change the speed-up."""


def describe(status: PlaybackStatus) -> str:
    """One sentence on where a replay is, e.g. ``at 42.50 s of 187.00 s (r120), 5x, paused``."""
    state = "at the end" if status.ended else ("paused" if status.paused else "playing")
    return (
        f"at {status.position:.2f} s of {status.duration:.2f} s (r{status.revision}), "
        f"{status.rate:g}x, {state}"
    )


def state_msg(status: PlaybackStatus) -> Any:
    """A replay status as a ``rosmc/ReplayState`` stamped with the wall time now."""
    return wire.ReplayState(
        stamp=rospy.Time.from_sec(time.time()),  # wall time, also under /use_sim_time
        position=status.position,
        duration=status.duration,
        revision=max(status.revision, 0),
        rate=status.rate,
        paused=status.paused,
        ended=status.ended,
        seeks=status.seeks,
    )


class ReplayControl:
    """Advertises the control service and the state topic of one replay; call :meth:`close`.

    Args:
        replay: What the service steers.
        prefix: The replay's prefix ("" for the live names), as in ``interface.prefixed``.
    """

    def __init__(self, replay: Steerable, prefix: str) -> None:
        self._replay = replay
        self._state = rospy.Publisher(
            interface.prefixed(interface.REPLAY_STATE_TOPIC, prefix),
            wire.ReplayState,
            queue_size=10,
            latch=True,
        )
        self._service = rospy.Service(
            interface.prefixed(interface.REPLAY_CONTROL_SERVICE, prefix),
            wire_srv.ReplayControl,
            self._on_control,
        )

    def publish(self, status: PlaybackStatus) -> None:
        """Tell subscribers where the replay is now."""
        self._state.publish(state_msg(status))

    def close(self) -> None:
        """Stop serving; the state topic stays latched until the node leaves."""
        self._service.shutdown()

    def _on_control(self, request: Any) -> Any:
        try:
            status = self._steer(request)
        except RosmcError as err:
            return self._answer(False, str(err))
        except Exception:  # a failing request must not kill the service thread
            _log.exception("replay control request %d failed", request.command)
            return self._answer(False, "the replay failed to do that (see its log)")
        return self._answer(True, describe(status), status)

    def _steer(self, request: Any) -> PlaybackStatus:
        replay = self._replay
        if request.command == Request.PAUSE:
            return replay.pause()
        if request.command == Request.RESUME:
            return replay.resume()
        if request.command == Request.SEEK:
            return replay.seek(request.time, relative=request.relative)
        if request.command == Request.SET_RATE:
            return replay.set_rate(request.rate)
        if request.command == Request.STATE:
            return replay.status()
        raise InvalidRequest(
            f"unknown replay command {request.command} (PAUSE=0, RESUME=1, SEEK=2, "
            "SET_RATE=3, STATE=4)"
        )

    def _answer(self, success: bool, message: str, status: PlaybackStatus | None = None) -> Any:
        state = state_msg(status if status is not None else self._replay.status())
        return wire_srv.ReplayControlResponse(success=success, message=message, state=state)
