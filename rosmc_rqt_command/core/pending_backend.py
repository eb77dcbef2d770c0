"""The command window's backend while its ROS node is still starting.

The standalone window is shown before the process is a ROS node (registering with the
master takes at least 100 ms, and forever while no master runs), so it is painted while
the node starts. Until the ROS bridge exists, :class:`PendingBackend` stands in: it keeps
what the window asks for and hands it to the bridge, in order, once there is one.
"""

from __future__ import annotations

from .requests import Backend, Request


def follows_replay(prefix: str) -> bool:
    """A window under ``prefix`` follows a replay, read-only ("" is the live server)."""
    return bool(prefix.strip().strip("/"))


class PendingBackend:
    """Stands in for the ROS bridge until it exists; nothing asked meanwhile is lost.

    Args:
        prefix: The namespace the bridge will follow (see :func:`follows_replay`).
    """

    def __init__(self, prefix: str = "") -> None:
        self.read_only = follows_replay(prefix)
        self._requests: list[Request] = []
        self._selection: tuple[list[str], list[str]] | None = None

    def request(self, request: Request) -> None:
        """Keep ``request`` for the bridge."""
        self._requests.append(request)

    def refresh(self) -> None:
        """Nothing to do: the bridge fetches the mission when it starts."""

    def publish_selection(self, skill_ids: list[str], marker_names: list[str]) -> None:
        """Keep the latest selection for the bridge to publish."""
        self._selection = (list(skill_ids), list(marker_names))

    def hand_over(self, backend: Backend) -> None:
        """Give ``backend`` every request kept, in order, and the latest selection."""
        requests, self._requests = self._requests, []
        for request in requests:
            backend.request(request)
        if self._selection is not None:
            backend.publish_selection(*self._selection)
            self._selection = None
