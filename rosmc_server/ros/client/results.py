"""What the operator services answer, as core-level values, and the client's own errors.

Every refusal the client raises is a core :class:`~rosmc_server.core.RosmcError`
subclass (one error family for callers);
:class:`~rosmc_server.core.errors.ServerUnavailable` means the mission server did not
answer at all.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...core import RosmcError, StaleRevision
from ...core.model.control import ControlCommand as ControlCommand  # callers import it from here


class RevisionConflict(StaleRevision):
    """The server refused a request made against an older revision (error code CONFLICT).

    Keeps the server's own sentence; ``current_revision`` is the server's revision
    when it refused.
    """

    def __init__(self, message: str, base_revision: int, current_revision: int) -> None:
        RosmcError.__init__(self, message)
        self.base_revision = base_revision
        self.current_revision = current_revision


@dataclass(frozen=True)
class Result:
    """An accepted request: the mission revision after it."""

    revision: int


@dataclass(frozen=True)
class SkillAdded(Result):
    """``add_skill`` succeeded; ``skill_id`` is the new skill's id."""

    skill_id: str


@dataclass(frozen=True)
class Transferred(Result):
    """``synchronize``/``unsynchronize`` succeeded for ``skill_ids`` (in transfer now)."""

    skill_ids: tuple[str, ...]
    note: str = ""  # what the operator should know: queued, barrier partners not synchronized


@dataclass(frozen=True)
class TeamTransferred(Transferred):
    """``synchronize_team`` succeeded: ``agents``' skills ``skill_ids`` are being uploaded."""

    agents: tuple[str, ...] = ()


@dataclass(frozen=True)
class ControlSent(Result):
    """A control command was sent to the robots of ``agents``."""

    agents: tuple[str, ...]
    note: str = ""  # e.g. queued for robots not heard since the server started


@dataclass(frozen=True)
class SkillRetried(Result):
    """``retry`` succeeded; ``new_skill_id`` is the fresh instance."""

    new_skill_id: str


@dataclass(frozen=True)
class BarrierAdded(Result):
    """``add_barrier`` succeeded; ``barrier_id`` is the new barrier's id."""

    barrier_id: str


@dataclass(frozen=True)
class MarkerAdded(Result):
    """``add_task_marker`` succeeded; ``name`` is the marker's (possibly generated) name."""

    name: str


@dataclass(frozen=True)
class EditUndone(Result):
    """``undo`` succeeded: ``summary`` says which edit it took back."""

    summary: str


@dataclass(frozen=True)
class MissionSaved(Result):
    """``save_mission``: the YAML document (if asked for), and the server-side path written."""

    document: str
    path_written: str
