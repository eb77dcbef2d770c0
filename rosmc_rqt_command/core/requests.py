"""What the widgets ask the mission server to do, and how it answered, as plain values.

A :class:`Request` is one typed call of a
:class:`~rosmc_server.ros.client.MissionClient` method: ``pick`` chooses the method
(``lambda c: c.delete_skills``) and :func:`ask` checks the arguments against its
signature, so mypy refuses a wrong call where the widget makes it. The ROS bridge runs
it on the client's worker against the revision the operator saw (``seen``): the client
fills in the base revision of every mutating call, and a change made by someone else
since is refused as a conflict. Nothing here imports the client or rospy at run time.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ParamSpec, Protocol

from rosmc_server.core.live.edit_history import EditKind

if TYPE_CHECKING:  # for the type checker only: the widgets never load the client
    from rosmc_server.ros.client import MissionClient

P = ParamSpec("P")
Pick = Callable[["MissionClient"], Callable[..., Any]]


@dataclass(frozen=True)
class Request:
    """One call of a client method, made against the revision the operator saw.

    Build it with :func:`ask` (which checks the arguments).

    Attributes:
        pick: Chooses the client method, e.g. ``lambda c: c.add_skill``.
        args: Positional arguments.
        kwargs: Keyword arguments.
        what: What the operator asked for, as words ("add take_off to drone").
        seen: The revision the operator saw (None: the client's own).
        on_answer: Called on the GUI thread with the answer (besides the message area).
        kind: The edit it makes, which undo can take back (None: not an edit).
    """

    pick: Pick = field(compare=False)
    args: tuple[Any, ...] = ()
    kwargs: Mapping[str, Any] = field(default_factory=dict)
    what: str = ""
    seen: int | None = None
    on_answer: Callable[[Answer], None] | None = field(default=None, compare=False)
    kind: EditKind | None = None
    operation: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "operation", _method_name(self.pick))

    def __call__(self, client: MissionClient) -> Any:
        """Make the call (on the client's worker thread)."""
        return self.pick(client)(*self.args, **self.kwargs)


def ask(
    pick: Callable[[MissionClient], Callable[P, object]],
    what: str = "",
    seen: int | None = None,
    on_answer: Callable[[Answer], None] | None = None,
    kind: EditKind | None = None,
) -> Callable[P, Request]:
    """A request maker taking exactly the arguments of the method ``pick`` chooses.

    ``ask(lambda c: c.delete_skills, "delete 'go'", revision)(["s1"])``; ``kind``: the
    edit the call makes (:class:`EditKind`), so that undo can take it back.
    """

    def make(*args: P.args, **kwargs: P.kwargs) -> Request:
        return Request(pick, args, kwargs, what, seen, on_answer, kind)

    return make


class _Name:
    """Stands in for the client to learn which method a pick chooses (its attribute name)."""

    def __getattr__(self, name: str) -> str:
        return name


def _method_name(pick: Pick) -> str:
    name: object = pick(_Name())  # type: ignore[arg-type]
    if not isinstance(name, str):
        raise TypeError("a request's pick must choose a client method, as lambda c: c.method")
    return name


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
