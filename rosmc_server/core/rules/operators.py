"""Who may change the mission: the operator allow-list, by ROS node name.

ROS 1 has no authentication: the caller id a node sends with a service call is whatever
the node says it is. The allow-list therefore keeps *mistakes* out (a test script, a second
team's GUI or a stray replay pointed at the live server), not an attacker on the network,
who can pick any name. An empty list lets every node in, as the server always did.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from ..errors import NotPermitted


@dataclass(frozen=True)
class OperatorAllowList:
    """Node names or name prefixes (``/ops/`` or ``/ops/*``) that may change the mission."""

    entries: tuple[str, ...] = ()

    @classmethod
    def of(cls, names: str | Iterable[object]) -> OperatorAllowList:
        """The allow-list of ``names`` (each a node name; a trailing ``*`` or ``/`` is a prefix).

        A string holds names separated by spaces or commas. ValueError for a non-name.
        """
        if isinstance(names, str):
            names = names.replace(",", " ").split()
        entries = []
        for name in names:
            if not isinstance(name, str) or not name.strip().rstrip("*"):
                raise ValueError(f"operator allow-list entry {name!r} is not a node name")
            entry = name.strip()
            entries.append(entry if entry.startswith("/") else "/" + entry)
        return cls(tuple(entries))

    @property
    def open(self) -> bool:
        """Whether every node may change the mission (the list is empty)."""
        return not self.entries

    def allows(self, caller: str) -> bool:
        """Whether the node ``caller`` (a full name such as ``/rosmc_command_1234``) may."""
        return self.open or any(_matches(entry, caller) for entry in self.entries)

    def check(self, caller: str, operation: str) -> None:
        """Raise NotPermitted, naming ``caller``, if it may not run ``operation``."""
        if not self.allows(caller):
            raise NotPermitted(
                f"node '{caller or 'unknown'}' may not call {operation}: it is not on the "
                f"mission server's operator allow-list (~operators: {', '.join(self.entries)})"
            )


def _matches(entry: str, caller: str) -> bool:
    if entry.endswith("*"):
        return caller.startswith(entry[:-1])
    if entry.endswith("/"):
        return caller.startswith(entry)
    return caller == entry
