"""What the widgets ask the mission server to do, and how it answered, as plain values.

Widgets build a :class:`Request` naming a :class:`~rosmc_server.ros.client.MissionClient`
method and its arguments; the ROS bridge runs it off the GUI thread and hands back an
:class:`Answer`. Keeping this as data keeps rospy out of the widgets.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

# Client methods that take a base revision (the rest do not change the plan).
MUTATING = frozenset(
    {
        "add_skill",
        "edit_skill",
        "delete_skills",
        "reorder",
        "synchronize",
        "synchronize_team",
        "unsynchronize",
        "retry",
        "skip",
        "add_barrier",
        "delete_barrier",
        "rename_marker",
        "new_mission",
        "load_mission",
        "undo",
    }
)


@dataclass(frozen=True)
class Request:
    """One call of a client method.

    Attributes:
        operation: The :class:`MissionClient` method, e.g. ``"add_skill"``.
        args: Positional arguments.
        kwargs: Keyword arguments.
        what: What the operator asked for, as words ("add take_off to drone").
        base_revision: The revision the operator saw (for mutating calls).
        on_answer: Called on the GUI thread with the answer (besides the message area).
    """

    operation: str
    args: tuple[Any, ...] = ()
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    what: str = ""
    base_revision: int | None = None
    on_answer: Callable[[Answer], None] | None = field(default=None, compare=False)


@dataclass(frozen=True)
class Answer:
    """How a request ended: ``value`` if it worked, else ``error`` (one sentence).

    ``conflict``: someone else changed the mission first (the view is being refreshed).
    ``unreachable``: the mission server did not answer.
    """

    request: Request
    value: Any = None
    error: str = ""
    conflict: bool = False
    unreachable: bool = False

    @property
    def ok(self) -> bool:
        """The server accepted the request."""
        return not self.error


class Backend(Protocol):
    """What the command widget needs from the outside world (the ROS bridge in practice)."""

    read_only: bool

    def request(self, request: Request) -> None:
        """Run ``request`` without blocking; the answer arrives later on the GUI thread."""

    def refresh(self) -> None:
        """Fetch a new snapshot of the mission."""

    def publish_selection(self, skill_ids: list[str], marker_names: list[str]) -> None:
        """Tell other GUIs (rviz) what is selected."""
