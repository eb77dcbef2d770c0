"""The replay bar's contact with ROS: the replay's state in, its control calls out, as signals.

ROS interface (behind the replay's prefix, e.g. ``/replay``):
    Subscribes ``/rosmc/replay/state`` (rosmc/ReplayState, latched).
    Calls ``/rosmc/replay/control`` (rosmc/ReplayControl) on a worker thread, one call at
    a time in the order asked, so the GUI thread never waits on the replay.
"""

from __future__ import annotations

import logging
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import rosmc.msg as wire
import rosmc.srv as wire_srv
import rospy
from python_qt_binding.QtCore import QObject, Signal

from rosmc_server import interface
from rosmc_server.recording.playback import PlaybackStatus

from .qt.replay_bar import ShownStatus

_log = logging.getLogger(__name__)
Request = wire_srv.ReplayControlRequest
CALL_TIMEOUT = 15.0
"""Seconds a control call waits for the replay's service to appear."""


def status_from_msg(msg: Any) -> ShownStatus:
    """A ``rosmc/ReplayState`` as the bar's status, with the wall time it held at."""
    status = PlaybackStatus(
        position=float(msg.position),
        duration=float(msg.duration),
        rate=float(msg.rate),
        paused=bool(msg.paused),
        seeks=int(msg.seeks),
        revision=int(msg.revision),
    )
    return ShownStatus(status, msg.stamp.to_sec())


class ReplayLink(QObject):  # type: ignore[misc]
    """Follows and steers one replay; create it on the GUI thread, :meth:`close` it after.

    Args:
        prefix: The replay's prefix (``/replay``).
    """

    state_received = Signal(object)  # ShownStatus
    refused = Signal(str)  # a control call that changed nothing: why, in one sentence

    def __init__(self, prefix: str) -> None:
        super().__init__()
        self._service = interface.prefixed(interface.REPLAY_CONTROL_SERVICE, prefix)
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="rosmc-replay")
        self._proxy: Any = None
        self._subscriber = rospy.Subscriber(
            interface.prefixed(interface.REPLAY_STATE_TOPIC, prefix),
            wire.ReplayState,
            lambda msg: self.state_received.emit(status_from_msg(msg)),
        )

    def pause(self) -> None:
        """Stop the replay where it is."""
        self._call(Request(command=Request.PAUSE))

    def resume(self) -> None:
        """Play on (from the start, at the end)."""
        self._call(Request(command=Request.RESUME))

    def seek(self, seconds: float) -> None:
        """Move to ``seconds`` since the recording started."""
        self._call(Request(command=Request.SEEK, time=float(seconds)))

    def set_rate(self, rate: float) -> None:
        """Play ``rate`` times as fast as recorded."""
        self._call(Request(command=Request.SET_RATE, rate=float(rate)))

    def close(self) -> None:
        """Stop following; pending calls are dropped."""
        self._subscriber.unregister()
        self._worker.shutdown(wait=False, cancel_futures=True)
        if self._proxy is not None:
            self._proxy.close()

    def _call(self, request: Any) -> None:
        self._worker.submit(self._run, request)

    def _run(self, request: Any) -> None:
        """Worker thread: one call; its answer's state (or why it failed) as a signal."""
        try:
            if self._proxy is None:
                rospy.wait_for_service(self._service, timeout=CALL_TIMEOUT)
                self._proxy = rospy.ServiceProxy(self._service, wire_srv.ReplayControl)
            answer = self._proxy(request)
        except (rospy.ROSException, rospy.ServiceException) as error:
            self._proxy = None
            self.refused.emit(f"The replay did not answer ({error}).")
            return
        if not answer.success:
            self.refused.emit(f"The replay refused: {answer.message}.")
        self.state_received.emit(status_from_msg(answer.state))
