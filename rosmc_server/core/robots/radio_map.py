"""Where the radio reaches: robots' signal readings, a radio model's prediction, and the
check that warns when a robot's synchronized task ends out of coverage.

:class:`RadioMap` keeps the newest reading per grid cell (it grows as robots report
from where they go), each robot's newest reading with a link (its last-link position),
and optionally a model's :class:`Prediction` (the simulator's radio model). A reading
keeps its stamp, so whoever shows it can say how old it is (:func:`reading_text`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

from ..model.model import SkillInstance, SkillStatus
from ..skills.params import Pose
from ..skills.policy import LostLinkPolicy

MEASURED_NEAR = 1.5
"""How far (m) a reading speaks for its surroundings when coverage is estimated."""


@dataclass(frozen=True)
class Reading:
    """One signal report: a robot's Wi-Fi signal and coverage where it was, when."""

    agent: str
    x: float
    y: float
    dbm: float
    covered: bool
    stamp: float


@dataclass(frozen=True)
class GridSpec:
    """A grid of square cells; cell (0, 0) is centred on the origin point."""

    origin_x: float
    origin_y: float
    resolution: float
    width: int
    height: int

    def index(self, x: float, y: float) -> int | None:
        """The row-major index of the cell holding (x, y); None outside the grid."""
        column = round((x - self.origin_x) / self.resolution)
        row = round((y - self.origin_y) / self.resolution)
        if 0 <= column < self.width and 0 <= row < self.height:
            return row * self.width + column
        return None

    def centre(self, index: int) -> tuple[float, float]:
        """The centre of the cell at ``index``."""
        row, column = divmod(index, self.width)
        return self.origin_x + column * self.resolution, self.origin_y + row * self.resolution


@dataclass(frozen=True)
class Prediction:
    """A radio model's coverage over a grid: signal (dBm) and covered, per cell."""

    grid: GridSpec
    signal: Sequence[float]
    covered: Sequence[bool]

    def at(self, x: float, y: float) -> tuple[float, bool] | None:
        """The predicted signal and coverage at (x, y); None outside the grid."""
        index = self.grid.index(x, y)
        if index is None or index >= len(self.signal) or index >= len(self.covered):
            return None
        return self.signal[index], self.covered[index]


@dataclass(frozen=True)
class Estimate:
    """Coverage at a point: from a reading nearby (``measured``) or from the model."""

    covered: bool
    dbm: float
    measured: bool


@dataclass
class RadioMap:
    """Robots' signal readings on a grid of ``resolution`` m, plus a model's prediction."""

    resolution: float = 1.0
    prediction: Prediction | None = None
    cells: dict[tuple[int, int], Reading] = field(default_factory=dict)
    last_link: dict[str, Reading] = field(default_factory=dict)

    def add(self, reading: Reading) -> None:
        """Take a reading (NaN signal or position: ignored); the newest per cell stays."""
        if not all(math.isfinite(v) for v in (reading.x, reading.y, reading.dbm)):
            return
        key = self._key(reading.x, reading.y)
        kept = self.cells.get(key)
        if kept is None or reading.stamp >= kept.stamp:
            self.cells[key] = reading
        last = self.last_link.get(reading.agent)
        if reading.covered and (last is None or reading.stamp >= last.stamp):
            self.last_link[reading.agent] = reading

    def _key(self, x: float, y: float) -> tuple[int, int]:
        return round(x / self.resolution), round(y / self.resolution)

    def readings(self) -> list[Reading]:
        """The newest reading of every cell."""
        return list(self.cells.values())

    def estimate(self, x: float, y: float) -> Estimate | None:
        """Coverage at (x, y): the nearest reading within :data:`MEASURED_NEAR`, else the
        model's prediction, else None (nothing is known there)."""
        near = [r for r in self._around(x, y) if math.hypot(r.x - x, r.y - y) <= MEASURED_NEAR]
        if near:
            best = min(near, key=lambda r: (math.hypot(r.x - x, r.y - y), -r.stamp))
            return Estimate(best.covered, best.dbm, True)
        predicted = self.prediction.at(x, y) if self.prediction is not None else None
        if predicted is None:
            return None
        return Estimate(predicted[1], predicted[0], False)

    def _around(self, x: float, y: float) -> Iterable[Reading]:
        reach = math.ceil(MEASURED_NEAR / self.resolution)
        cx, cy = self._key(x, y)
        for dx in range(-reach, reach + 1):
            for dy in range(-reach, reach + 1):
                reading = self.cells.get((cx + dx, cy + dy))
                if reading is not None:
                    yield reading


def reading_text(reading: Reading, now: float) -> str:
    """A reading as operators read it: ``-72 dBm 26 s ago`` (``now`` if under a second)."""
    age = now - reading.stamp
    when = "now" if age < 1.0 else f"{age:.0f} s ago"
    return f"{reading.dbm:.0f} dBm {when}"


def plan_end(task: Sequence[SkillInstance]) -> Pose | None:
    """Where the robot's synchronized task takes it: the pose of the last skill still to
    run (synchronized, not settled) that has a pose parameter; None if none has one.

    A skill without a pose parameter after it (say ``return_to_lander``) is not known to
    move the robot, so it does not count.
    """
    end: Pose | None = None
    for skill in task:
        if skill.status is SkillStatus.IDLE or skill.is_settled:  # blueprint, or done
            continue
        poses = [value for value in skill.params.values() if isinstance(value, Pose)]
        if poses:
            end = poses[-1]
    return end


def leaves_robot_out(in_force: LostLinkPolicy | None, default: LostLinkPolicy | None) -> bool:
    """Whether the policy a robot reports (else the library's default) leaves it out of
    coverage once idle there."""
    policy = in_force or default
    return policy is None or policy.leaves_robot_out()


def coverage_warning(
    task: Sequence[SkillInstance],
    radio: RadioMap,
    in_force: LostLinkPolicy | None,
    default: LostLinkPolicy | None,
) -> str:
    """One sentence if the task ends out of coverage under a policy that leaves the robot
    there; "" otherwise (also when nothing is known of the coverage there)."""
    end = plan_end(task)
    if end is None or not leaves_robot_out(in_force, default):
        return ""
    estimate = radio.estimate(end.x, end.y)
    if estimate is None or estimate.covered:
        return ""
    source = "measured" if estimate.measured else "predicted"
    return (
        f"the task ends out of coverage at ({end.x:.1f}, {end.y:.1f}) ({source} "
        f"{estimate.dbm:.0f} dBm) and the lost-link policy would leave the robot there"
    )
