"""The mission's science as the operator sees it: the score, and where the stones are.

What the simulator (or a real science team's tally) publishes on ``/rosmc/sim/science``,
as plain values for the command line and the GUIs, and worded the same way for both.
"""

from __future__ import annotations

from dataclasses import dataclass

from .vocabulary import counted

# Who identified a region's stones, as the operator reads it.
IDENTIFIED_WORDS = {
    "": "not identified",
    "science_rover": "identified by the science rover",
    "collaborative": "identified by both rovers",
}


@dataclass(frozen=True)
class RegionScience:
    """A discovered region for sampling stones and what is known about it."""

    name: str
    x: float
    y: float
    radius: float
    max_score: float
    stones_left: int
    identified_by: str  # "", "science_rover" or "collaborative"

    def sentence(self) -> str:
        """E.g. ``RSS A at (16, 9): identified by both rovers, 2 stones left (best 1)``."""
        how = IDENTIFIED_WORDS.get(self.identified_by, f"identified by {self.identified_by}")
        return (
            f"{self.name} at ({self.x:g}, {self.y:g}): {how}, "
            f"{counted(self.stones_left, 'stone')} left (best {self.max_score:g})"
        )


@dataclass(frozen=True)
class Science:
    """The score so far, the stones delivered and the discovered regions."""

    score: float
    stones_delivered: int
    regions: tuple[RegionScience, ...] = ()

    def headline(self) -> str:
        """One line: the score and what was delivered and discovered."""
        found = ", ".join(r.name for r in self.regions) or "none yet"
        return (
            f"science score {self.score:.2f}: {counted(self.stones_delivered, 'stone')} delivered "
            f"to the lander; regions discovered: {found}"
        )

    def lines(self) -> list[str]:
        """The headline, then one line per discovered region."""
        return [self.headline(), *(f"  {r.sentence()}" for r in self.regions)]

    def to_dict(self) -> dict[str, object]:
        """Plain data (for ``--json``)."""
        return {
            "score": self.score,
            "stones_delivered": self.stones_delivered,
            "regions": [vars(region).copy() for region in self.regions],
        }
