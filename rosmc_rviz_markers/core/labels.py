"""Labels that do not write over each other, laid out as the shipped rviz views see them.

rviz draws camera-facing text where it is told and never moves it out of the way, so at a
busy place (a region with robots and task markers) the labels would pile up. Here every
label is a box on the *view plane* of the shipped views ("Whole site", "Work area": both
look north, 1.2 and 1.25 rad below the horizon): horizontally its map ``x``, vertically
``y sin(pitch) + z cos(pitch)`` (metres, perspective ignored). :func:`layout` slides the
movable labels south (down the screen) just as far as needed to clear every label above
them and every fixed box (the robots' status blocks), so the labels stack in a column.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from rosmc_server.core.views.geometry import CHAR_WIDTH

LINE_SPACING = 1.25  # from one line's centre to the next, in letter heights
VIEW_PITCH = 1.25  # the steepest shipped view looks north, this far below the horizon (rad)
GAP = 0.15  # between two stacked labels (view-plane metres)


@dataclass(frozen=True)
class Box:
    """A label's rectangle on the view plane (metres)."""

    left: float
    right: float
    bottom: float
    top: float

    def overlaps(self, other: Box) -> bool:
        """Whether the two rectangles share more than an edge."""
        return (
            self.left < other.right
            and other.left < self.right
            and self.bottom < other.top
            and other.bottom < self.top
        )


@dataclass(frozen=True)
class Label:
    """A camera-facing text block centred at map ``(x, y, z)``.

    ``height`` is the letter height; ``spacing`` the distance between line centres
    (default :data:`LINE_SPACING` letter heights).
    """

    key: str
    x: float
    y: float
    z: float
    lines: tuple[str, ...]
    height: float
    spacing: float = 0.0

    @property
    def width(self) -> float:
        """The widest line's width (metres)."""
        return max((len(line) for line in self.lines), default=0) * self.height * CHAR_WIDTH

    def box(self, south: float = 0.0, pitch: float = VIEW_PITCH) -> Box:
        """The label's box on the view plane when moved ``south`` metres (map -y)."""
        spacing = self.spacing or self.height * LINE_SPACING
        half = (spacing * (len(self.lines) - 1) + self.height) / 2
        centre = (self.y - south) * math.sin(pitch) + self.z * math.cos(pitch)
        return Box(self.x - self.width / 2, self.x + self.width / 2, centre - half, centre + half)


class _Placed:
    """Boxes already placed, bucketed by 2 m cells of the view plane, so that a label is
    checked against its neighbours only (a field of hundreds of labels stays cheap)."""

    CELL = 2.0

    def __init__(self, boxes: Iterable[Box] = ()) -> None:
        self._cells: dict[tuple[int, int], list[Box]] = {}
        for box in boxes:
            self.add(box)

    def _keys(self, box: Box) -> list[tuple[int, int]]:
        xs = range(math.floor(box.left / self.CELL), math.floor(box.right / self.CELL) + 1)
        vs = range(math.floor(box.bottom / self.CELL), math.floor(box.top / self.CELL) + 1)
        return [(x, v) for x in xs for v in vs]

    def add(self, box: Box) -> None:
        """Place ``box``."""
        for key in self._keys(box):
            self._cells.setdefault(key, []).append(box)

    def hits(self, box: Box) -> list[Box]:
        """The placed boxes that ``box`` overlaps."""
        found: dict[int, Box] = {}
        for key in self._keys(box):
            for other in self._cells.get(key, ()):
                if box.overlaps(other):
                    found[id(other)] = other
        return list(found.values())


def layout(
    labels: Sequence[Label],
    fixed: Iterable[Box] = (),
    pitch: float = VIEW_PITCH,
    step: float = 0.0,
    keep: Mapping[str, float] | None = None,
    prefer: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """How far south (map metres, >= 0) to move each of ``labels`` so no two boxes overlap.

    Labels are taken from the top of the screen down; each moves the least that clears
    every box placed before it and every ``fixed`` box (a column of labels at one place).
    With a ``step``, moves are whole steps (so that a small change moves no label).

    Laying out again after a change: labels named in ``keep`` (those that did not change)
    are placed first, that far south, wherever they are clear; the others then find room
    around them, each at its ``prefer`` offset if that is clear. A label that changes
    then moves itself, not the labels below it in its column.
    """
    keep, prefer = keep or {}, prefer or {}
    placed = _Placed(fixed)
    out: dict[str, float] = {}
    order = sorted(labels, key=lambda label: (-label.box(0.0, pitch).top, label.x, label.key))
    rest = []
    for label in order:
        if label.key in keep and not placed.hits(box := label.box(keep[label.key], pitch)):
            out[label.key] = keep[label.key]
            placed.add(box)
        else:
            rest.append(label)
    for label in rest:
        wanted = prefer.get(label.key)
        if wanted is not None and not placed.hits(box := label.box(wanted, pitch)):
            out[label.key] = wanted
            placed.add(box)
            continue
        out[label.key] = south = _clear_south(label, placed, pitch, step)
        placed.add(label.box(south, pitch))
    return out


def _clear_south(label: Label, placed: _Placed, pitch: float, step: float) -> float:
    """The least move south that clears every placed box."""
    rise = math.sin(pitch)
    south = 0.0
    while hits := placed.hits(box := label.box(south, pitch)):
        # just below the lowest box it hits (the label only moves down the screen)
        lowest = min(other.bottom for other in hits)
        south += (box.top - lowest + GAP) / rise
        if step > 0:
            south = math.ceil(south / step - 1e-9) * step
    return south


def overlapping(boxes: Sequence[Box]) -> list[tuple[int, int]]:
    """The index pairs of the boxes that overlap (for checks and tests)."""
    return [
        (i, j)
        for i in range(len(boxes))
        for j in range(i + 1, len(boxes))
        if boxes[i].overlaps(boxes[j])
    ]
