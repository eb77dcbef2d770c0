"""The operator station on one screen: where rviz and the command window go, and the clock.

Both windows start side by side on the screen's available area (without the desktop's
panels): rviz on the left, the command window on the right, without overlap. The command
window takes a bit less than half (it wraps and scrolls down to about 500 px); rviz takes the
rest, so the 3D view stays as wide as it can. The mission clock reads the same in both.
"""

from __future__ import annotations

from dataclasses import dataclass

COMMAND_SHARE = 0.47  # of the screen's width, for the command window
COMMAND_MIN_WIDTH = 560  # narrower, the task columns have too little room beside the panels
COMMAND_MAX_WIDTH = 900  # wider, rviz's 3D view would lose more than the tables gain
TITLE_BAR = 32  # a window manager's title bar above each window (not in its geometry)
GAP = 4  # between the two windows (their frames)


@dataclass(frozen=True)
class Rect:
    """A window's place on the screen: left, top, width and height in pixels."""

    x: int
    y: int
    width: int
    height: int

    @property
    def right(self) -> int:
        """The first column right of the rectangle."""
        return self.x + self.width

    def overlaps(self, other: Rect) -> bool:
        """Whether the two rectangles share a pixel."""
        return (
            self.x < other.right
            and other.x < self.right
            and self.y < other.y + other.height
            and other.y < self.y + self.height
        )


@dataclass(frozen=True)
class Station:
    """Where each window of the station starts."""

    rviz: Rect
    command: Rect


def split_screen(screen: Rect) -> Station:
    """rviz left, the command window right, both inside ``screen`` (its available area).

    A screen narrower than two command windows (under 1120 px) is not split: each window
    takes all of it, one over the other.
    """
    top, height = screen.y + TITLE_BAR, screen.height - TITLE_BAR
    if screen.width < 2 * COMMAND_MIN_WIDTH:
        whole = Rect(screen.x, top, screen.width, height)
        return Station(rviz=whole, command=whole)
    wanted = round(screen.width * COMMAND_SHARE)
    command_width = min(max(wanted, COMMAND_MIN_WIDTH), COMMAND_MAX_WIDTH)
    rviz_width = screen.width - command_width - GAP
    return Station(
        rviz=Rect(screen.x, top, rviz_width, height),
        command=Rect(screen.x + rviz_width + GAP, top, command_width, height),
    )


MISSION = "mission time"  # the simulation's time since it started
REPLAY = "replay time"  # the replay's position in its recording
UTC = "UTC"  # no simulation: the time of day


def clock_text(seconds: float | None, label: str = MISSION) -> str:
    """The mission clock as shown, e.g. ``mission time 1:02:03``; dashes while not known."""
    if seconds is None:
        return f"{label} –:––:––"
    whole = max(0, int(seconds))
    hours, rest = divmod(whole, 3600)
    return f"{label} {hours % 24 if label == UTC else hours}:{rest // 60:02d}:{rest % 60:02d}"


def rviz_config_at(text: str, place: Rect) -> str:
    """An rviz config (its text) whose window starts at ``place``; nothing else changes.

    Only the four numbers of the top-level ``Window Geometry`` block are replaced (the file
    is rewritten as text, so rviz reads everything else exactly as written).
    """
    wanted = {"Height": place.height, "Width": place.width, "X": place.x, "Y": place.y}
    lines = text.splitlines(keepends=True)
    inside = False
    for index, line in enumerate(lines):
        if not line.startswith(" "):
            inside = line.rstrip() == "Window Geometry:"
            continue
        key = line.strip().split(":", 1)[0]
        if inside and line.startswith("  ") and not line.startswith("   ") and key in wanted:
            lines[index] = f"  {key}: {wanted[key]}\n"
    return "".join(lines)
