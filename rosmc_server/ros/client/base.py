"""The read side of :class:`~.mission_client.MissionClient` and its revision tracking."""

from __future__ import annotations

import threading
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any, Self

from rosmc.msg import ErrorCode

from ...conversions import library_from_msg, param_to_msg
from ...conversions.request_fields import FIRST_REVISION
from ...core import Library, MissionState, SkillInstance, SkillSpec
from .connection import ServiceCaller, raise_for


class ClientBase:
    """Connections, the cached library, mission snapshots and the known revision.

    Thread-safe: one lock covers the known revision across a request and its answer.

    Args:
        timeout: Seconds to wait for the server to appear (per connection).
        prefix: Namespace before every service name, e.g. ``/replay`` to read a replay.
    """

    def __init__(self, timeout: float = 5.0, prefix: str = "") -> None:
        self._caller = ServiceCaller(timeout, prefix)
        self.revision: int | None = None
        self.journal_alert = ""
        """What the server's last resume could not recover from its journal, as of the last
        mission fetched ("" if nothing)."""
        self.epoch = ""
        """The mission's history as of the last mission fetched (new when a resume lost
        history)."""
        self._library: Library | None = None
        self._kinds: dict[str, tuple[str, str]] = {}
        self._seen: int | None = None  # the revision a GUI's operator saw (see against())
        self._lock = threading.RLock()

    @property
    def prefix(self) -> str:
        """The namespace before every service name ("" for the live server)."""
        return self._caller.prefix

    @property
    def timeout(self) -> float:
        """Seconds to wait for the server to answer."""
        return self._caller.timeout

    def close(self) -> None:
        """Close the connections to the server (they reopen when needed)."""
        self._caller.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    @contextmanager
    def against(self, seen: int | None) -> Iterator[None]:
        """Make the block's mutating calls against ``seen``, the revision an operator saw.

        Each call without its own ``base_revision`` is then made against ``seen``, or
        against the client's own last result if that is newer (calls run in order, so a
        quick second click is not refused because of the first). ``seen`` None or below
        :data:`FIRST_REVISION` (nothing shown yet; no mission is at 0, which on the wire means
        no check): the client's known revision, as outside the block. Holds the client's lock
        for the block.
        """
        shown = seen if seen is not None and seen >= FIRST_REVISION else None
        with self._lock:
            before, self._seen = self._seen, shown
            try:
                yield
            finally:
                self._seen = before

    def forget_newer_than(self, revision: int) -> None:
        """A mission snapshot at ``revision`` arrived: a known revision above it was another
        server's (a new mission server process), so later calls are made against the new one."""
        with self._lock:
            if self.revision is not None and self.revision > revision:
                self.revision = None

    # -- queries -------------------------------------------------------------------
    def library(self) -> Library:
        """The skill library (fetched once, then cached)."""
        with self._lock:
            if self._library is None:
                self._library = library_from_msg(self._caller.call("get_library").library)
            return self._library

    def forget_library(self) -> None:
        """Fetch the library anew when next needed (the server restarted, maybe with
        another library)."""
        with self._lock:
            self._library = None

    def get_mission(self) -> MissionState:
        """The current mission; the client now knows its revision."""
        with self._lock:
            state = self.fetch_mission()
            self.revision = state.revision
            return state

    def fetch_mission(self) -> MissionState:
        """The current mission, leaving the client's known revision as it was."""
        response = self._caller.call("get_mission")  # an UnpackedGetMissionResponse
        self.journal_alert = str(response.journal_alert)
        self.epoch = str(response.epoch)
        state = MissionState(response.content, response.revision)
        self._kinds.update({s.id: (s.agent, s.skill) for s in state.skills()})
        return state

    def skill(self, skill_id: str) -> SkillInstance:
        """The current instance of a skill (NotFound if there is none)."""
        return self.fetch_mission().skill(skill_id)

    def skill_spec(self, skill_id: str) -> SkillSpec:
        """The library schema of an existing skill (NotFound if there is no such skill)."""
        return self.library().skill(*self._kind(skill_id))

    # -- internals ---------------------------------------------------------------------
    def _kind(self, skill_id: str) -> tuple[str, str]:
        """The agent and skill name of a skill id (they never change, so they are cached)."""
        if skill_id not in self._kinds:
            self.skill(skill_id)  # fills the cache, or raises NotFound
        return self._kinds[skill_id]

    def _parameters(
        self, agent: str, skill: str, params: Mapping[str, object], bindings: Mapping[str, str]
    ) -> list[Any]:
        spec = self.library().skill(agent, skill)
        msgs = [param_to_msg(n, spec.parameter(n).check(raw, skill)) for n, raw in params.items()]
        msgs += [param_to_msg(n, spec.parameter(n).default, m) for n, m in bindings.items()]
        return msgs

    def _mutate(
        self,
        operation: str,
        base_revision: int | None = None,
        retry_on_conflict: bool = False,
        **fields: Any,
    ) -> Any:
        with self._lock:
            base = self._base(base_revision)
            response = self._caller.call(operation, base_revision=base, **fields)
            conflict = response.error_code == ErrorCode.CONFLICT
            if conflict and retry_on_conflict and base_revision is None:
                base = self.get_mission().revision
                response = self._caller.call(operation, base_revision=base, **fields)
            raise_for(response, base)
            self.revision = response.revision
            return response

    def _base(self, base_revision: int | None) -> int:
        if base_revision is not None:
            return base_revision
        if self._seen is not None:
            return max(self._seen, self.revision if self.revision is not None else -1)
        if self.revision is None:
            return self.get_mission().revision
        return self.revision
