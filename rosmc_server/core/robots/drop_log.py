"""Counted, rate-limited warnings for what the robot link drops.

Whatever reaches a node from outside — a forged datagram, a command for another robot, a
signal it cannot read — is dropped and must be visible, but a flood of it must not flood
the log as well: 5,000 junk datagrams once gave 640 warnings in 2.4 s. :class:`DropLog`
counts every drop per reason and words a warning for the first one of a reason, then at
most one per ``period`` seconds per reason, saying how many came since.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..views.vocabulary import counted

LOG_PERIOD = 30.0  # seconds between two warnings for the same reason


@dataclass
class DropLog:
    """Counts drops by reason; says when one is worth a warning.

    Args:
        what: What is dropped, as a countable noun (``radio datagram``, ``command``).
        period: Seconds between two warnings for the same reason.
    """

    what: str
    period: float = LOG_PERIOD
    _counts: dict[str, int] = field(default_factory=dict)
    _unlogged: dict[str, int] = field(default_factory=dict)
    _next: dict[str, float] = field(default_factory=dict)

    @property
    def total(self) -> int:
        """Drops of every reason so far."""
        return sum(self._counts.values())

    def count(self, reason: str) -> int:
        """Drops of ``reason`` so far."""
        return self._counts.get(reason, 0)

    def drop(self, reason: str, detail: str, now: float) -> str | None:
        """Count one drop at ``now`` (monotonic seconds); the warning to log, or None.

        ``reason`` is the sentence that says why (one per kind of drop); ``detail`` what
        is known of this one (who sent it), shown in the warning for it.
        """
        self._counts[reason] = self._counts.get(reason, 0) + 1
        self._unlogged[reason] = self._unlogged.get(reason, 0) + 1
        if now < self._next.get(reason, float("-inf")):
            return None
        first = reason not in self._next
        self._next[reason] = now + self.period
        since, self._unlogged[reason] = self._unlogged[reason], 0
        total = self._counts[reason]
        if first:
            return (
                f"dropped a {self.what} {detail}: {reason} (more like it are counted and "
                f"logged at most every {self.period:g} s)"
            )
        return (
            f"dropped {counted(since, 'more ' + self.what)} ({total} in all) for the same reason, "
            f"{reason}; the last {detail}"
        )
