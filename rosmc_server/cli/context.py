"""What every ``rosmc`` command works with: the parsed arguments, a client and the output."""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict, dataclass, field
from typing import Any, TextIO

from ..core import AgentStatus
from ..core.views.science import Science
from ..core.world.site_source import SiteInForce
from ..ros.client import MissionClient, MissionWatch, Result, ScienceWatch, SiteWatch, init_node
from ..ros.client.latched import LatchedWatch, T

# How long `rosmc status` waits for the robots' states (the server publishes at 2 Hz).
STATES_WAIT = 1.5


class UsageError(Exception):
    """The command line is malformed in a way argparse cannot see (exit code 2)."""


@dataclass
class Context:
    """The parsed arguments, the mission client and where output goes."""

    args: argparse.Namespace
    client: MissionClient
    out: TextIO = field(default_factory=lambda: sys.stdout)

    @property
    def json(self) -> bool:
        """Whether to print JSON instead of text."""
        return bool(self.args.json)

    @property
    def revision(self) -> int | None:
        """The base revision the user gave (--revision), if any."""
        revision: int | None = self.args.revision
        return revision

    def against(self) -> dict[str, Any]:
        """How a change names its base revision: ``--revision`` if given, else the current one.

        Without ``--revision`` the command fetched the revision itself a moment before,
        so a conflict only means someone else was a few milliseconds faster: the change
        is retried once against the newer mission (the server checks every rule again).
        With ``--revision``, a conflict is reported (exit code 1).
        """
        return {"base_revision": self.revision, "retry_on_conflict": self.revision is None}

    def emit(self, text: str, data: Any) -> None:
        """Print ``text``, or ``data`` as JSON with --json."""
        if self.json:
            print(json.dumps(data, indent=2), file=self.out, flush=True)
        elif text:
            print(text, file=self.out, flush=True)

    def emit_result(self, result: Result, text: str | None = None) -> int:
        """Print a result (default text: the new revision); return exit code 0."""
        line = text if text is not None else f"revision {result.revision}"
        note = getattr(result, "note", "")
        self.emit(f"{line}\n{note}" if note else line, asdict(result))
        return 0

    def science(self) -> Science | None:
        """The science state if someone publishes it (waiting briefly for it); else None."""
        init_node()
        return self._latched(ScienceWatch())

    def site(self) -> SiteInForce | None:
        """The site map in force if the server publishes it (waiting briefly); else None."""
        init_node()
        return self._latched(SiteWatch())

    def _latched(self, watch: LatchedWatch[T]) -> T | None:
        try:
            return watch.wait(min(self.client.timeout, STATES_WAIT))
        finally:
            watch.close()

    def agent_states(self) -> dict[str, AgentStatus]:
        """The robots' latest states, waiting briefly for them; empty if none arrive."""
        init_node()
        watch = MissionWatch(events=False, states=True)
        try:
            return watch.wait_agent_states(min(self.client.timeout, STATES_WAIT)) or {}
        finally:
            watch.close()
