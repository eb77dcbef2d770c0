"""A recording's timeline as a picture: one lane per robot, one bar per skill execution.

The SVG is plain text written here (no plotting library). Bars are coloured by
what the robot did and how it ended: teal for running and success, red for a
failure, olive while waiting at a barrier, grey while paused; a stopped or
unfinished execution has a dashed outline. A barrier release is a vertical line
joining its members' lanes. Above the lanes, the operator's changes are marks on the
time axis (blue: sync, orange: unsync, purple: other edits); a robot's link outages
are shaded amber on its lane; the score is a line in a panel below the lanes.
PNG goes through ImageMagick's ``convert``.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import tempfile
from pathlib import Path
from xml.sax.saxutils import escape, quoteattr

from rosmc_server.core import RosmcError, SkillStatus
from rosmc_server.recording.timeline import BarrierRelease, Interval, OperatorMark, Timeline

TEAL = "#1b9e8f"
RED = "#d1453b"
OLIVE = "#8d8d2b"
GREY = "#9a9a9a"
INK = "#222222"
OUTAGE = "#f9c46b"  # amber shading: the link was down
MARK_COLOURS = {"sync": "#2b6cc4", "unsync": "#e8731a", "edit": "#7b4fa0"}
SCORE = "#1f4e9c"

LABEL_WIDTH = 170
PLOT_WIDTH = 1000
LANE_HEIGHT = 46
BAR_HEIGHT = 26
TOP = 48
MARK_HEIGHT = 12  # operator marks sit in a strip just above the lanes
SCORE_PANEL = 72  # the score panel's height, below the lanes, when a score was recorded
PNG_DENSITY = 144  # dpi: twice the SVG's pixel size, sharp on high-resolution screens
CHAR_WIDTH = 6.0  # about, in 11 px sans-serif: how much of a label fits its bar


class TimelineExportError(RosmcError):
    """The timeline picture cannot be written (format, tool or file)."""


def interval_colour(interval: Interval) -> str:
    """The fill of an interval's bar."""
    if interval.status is SkillStatus.SYNCWAITING:
        return OLIVE
    if interval.status is SkillStatus.PAUSED:
        return GREY
    return RED if interval.outcome is SkillStatus.FAILURE else TEAL


def render_svg(timeline: Timeline, title: str = "") -> str:
    """The timeline as an SVG document."""
    lanes = list(timeline.lanes)
    span = max(timeline.duration, 1e-3)
    scale = PLOT_WIDTH / span
    lanes_bottom = TOP + LANE_HEIGHT * len(lanes)
    score_room = SCORE_PANEL if timeline.score else 0
    overlays = bool(timeline.score or timeline.marks or timeline.outages)
    height = TOP + LANE_HEIGHT * max(len(lanes), 1) + 86 + score_room + (20 if overlays else 0)
    width = LABEL_WIDTH + PLOT_WIDTH + 30
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" font-family="DejaVu Sans, Arial, sans-serif" '
        'font-size="11" stroke="none">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
        f'<text x="10" y="22" font-size="15" font-weight="bold">{escape(title)}</text>',
    ]
    for row, agent in enumerate(lanes):
        y = TOP + row * LANE_HEIGHT
        shade = "#f4f4f4" if row % 2 == 0 else "#ffffff"
        out.append(f'<g class="lane" data-agent={quoteattr(agent)}>')
        out.append(
            f'<rect x="{LABEL_WIDTH}" y="{y}" width="{PLOT_WIDTH}" height="{LANE_HEIGHT}" '
            f'fill="{shade}"/>'
        )
        out.append(
            f'<text x="{LABEL_WIDTH - 10}" y="{y + LANE_HEIGHT / 2 + 4}" text-anchor="end" '
            f'font-size="12" font-weight="bold">{escape(agent)}</text>'
        )
        out += [
            f'<rect class="outage" x="{_x(start, scale)}" y="{y}" '
            f'width="{max(round((end - start) * scale, 2), 1.0)}" height="{LANE_HEIGHT}" '
            f'fill="{OUTAGE}"><title>link down {start:.1f}-{end:.1f} s</title></rect>'
            for who, start, end in timeline.outages
            if who == agent
        ]
        out += [_bar(interval, y, scale) for interval in timeline.lanes[agent]]
        out.append("</g>")
    row_of = {agent: row for row, agent in enumerate(lanes)}
    out += [_release(release, row_of, scale) for release in timeline.releases]
    out += [_mark(mark, scale) for mark in timeline.marks]
    if timeline.score:
        out += _score(timeline.score, span, scale, lanes_bottom)
    out += _axis(span, scale, lanes_bottom + score_room)
    if overlays:
        out += _overlay_legend(height - 36)
    out += _legend(height - 16)
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_timeline(timeline: Timeline, path: str | Path, title: str = "") -> Path:
    """Write the timeline to ``path``: ``.svg``, or ``.png`` through ImageMagick.

    Raises:
        TimelineExportError: Another suffix, PNG without ``convert`` on PATH, or the file
            cannot be written.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".svg", ".png"):
        raise TimelineExportError(f"cannot write a timeline as {path.name}: use .svg or .png")
    svg = render_svg(timeline, title)
    try:
        if suffix == ".svg":
            path.write_text(svg, encoding="utf-8")
            return path
        convert = shutil.which("convert")
        if convert is None:
            raise TimelineExportError(
                "PNG needs ImageMagick ('convert' is not on PATH; 'make setup' installs it); "
                "write an .svg instead"
            )
        with tempfile.TemporaryDirectory() as tmp:
            source = Path(tmp) / "timeline.svg"
            source.write_text(svg, encoding="utf-8")
            done = subprocess.run(
                [convert, "-density", str(PNG_DENSITY), str(source), str(path)],
                capture_output=True,
                text=True,
                check=False,
            )
        if done.returncode != 0:
            reason = done.stderr.strip().splitlines()[-1:] or ["no message"]
            raise TimelineExportError(f"convert could not write {path}: {reason[0]}")
    except OSError as err:
        raise TimelineExportError(f"cannot write {path}: {err.strerror}") from err
    return path


def _x(seconds: float, scale: float) -> float:
    return round(LABEL_WIDTH + seconds * scale, 2)


def _bar(interval: Interval, lane_y: float, scale: float) -> str:
    x = _x(interval.start, scale)
    width = max(round((interval.end - interval.start) * scale, 2), 2.0)
    y = lane_y + (LANE_HEIGHT - BAR_HEIGHT) / 2
    ended = interval.outcome.name if interval.outcome is not None else "still going"
    if interval.outcome is SkillStatus.IDLE_SYNCHRONIZED:
        ended = "stopped"
    dashed = interval.outcome in (None, SkillStatus.IDLE_SYNCHRONIZED)
    outline = f'stroke="{INK}" stroke-dasharray="4 2"' if dashed else 'stroke="white"'
    label = interval.label + (f" #{interval.attempt}" if interval.attempt > 1 else "")
    tip = (
        f"{interval.agent} {interval.skill_id} ({interval.skill}) {interval.status.name} "
        f"{interval.start:.2f}-{interval.end:.2f} s, then {ended}"
        + (f", barrier {interval.barrier}" if interval.barrier else "")
    )
    parts = [
        f'<g class="bar"><title>{escape(tip)}</title><rect x="{x}" y="{y}" width="{width}" '
        f'height="{BAR_HEIGHT}" rx="3" fill="{interval_colour(interval)}" {outline}/>'
    ]
    fits = _fit(label, width - 8)
    if fits:
        parts.append(
            f'<text x="{x + 4}" y="{y + BAR_HEIGHT / 2 + 4}" fill="white">{escape(fits)}</text>'
        )
    parts.append("</g>")
    return "".join(parts)


def _fit(label: str, room: float) -> str:
    """``label``, cut short with an ellipsis to fit ``room`` pixels ("" if too little is left)."""
    chars = int(room / CHAR_WIDTH)
    if len(label) <= chars:
        return label
    return label[: chars - 1] + "…" if chars >= 4 else ""


def _release(release: BarrierRelease, row_of: dict[str, int], scale: float) -> str:
    rows = sorted(row_of[agent] for agent, _ in release.members if agent in row_of)
    if not rows:
        return ""
    x = _x(release.time, scale)
    top = TOP + rows[0] * LANE_HEIGHT + 4
    bottom = TOP + (rows[-1] + 1) * LANE_HEIGHT - 4
    dots = "".join(
        f'<circle cx="{x}" cy="{TOP + row * LANE_HEIGHT + LANE_HEIGHT / 2}" r="4" fill="{INK}"/>'
        for row in rows
    )
    tip = f"barrier {release.barrier} released at {release.time:.2f} s"
    return (
        f'<g class="release"><title>{escape(tip)}</title>'
        f'<line x1="{x}" y1="{top}" x2="{x}" y2="{bottom}" '
        f'stroke="{INK}" stroke-width="2"/>{dots}</g>'
    )


def _mark(mark: OperatorMark, scale: float) -> str:
    x = _x(mark.time, scale)
    return (
        f'<rect class="mark" data-kind="{mark.kind}" x="{x - 1.5}" y="{TOP - MARK_HEIGHT - 2}" '
        f'width="3" height="{MARK_HEIGHT}" fill="{MARK_COLOURS[mark.kind]}">'
        f"<title>{escape(f'{mark.time:.1f} s: {mark.summary}')}</title></rect>"
    )


def score_y(value: float, top: float, highest: float) -> float:
    """Where a score value is drawn in the panel whose top is at ``top``."""
    plot = SCORE_PANEL - 22  # 10 px margin above, 12 below
    return round(top + 10 + plot * (1.0 - value / highest), 2) if highest > 0 else top + 10 + plot


def _score(
    score: tuple[tuple[float, float], ...], span: float, scale: float, top: float
) -> list[str]:
    """The score as a step line: it holds each value until the next record.

    Drawn as separate segments, not a polyline: ImageMagick's SVG renderer joins a
    long polyline's ends with stray diagonals.
    """
    highest = max(value for _, value in score)
    style = f'stroke="{SCORE}" stroke-width="3" stroke-linecap="square"'
    out = [
        f'<text x="{LABEL_WIDTH - 10}" y="{top + SCORE_PANEL / 2 + 4}" text-anchor="end" '
        f'font-size="12" font-weight="bold">score (max {highest:g})</text>',
        f'<line x1="{LABEL_WIDTH}" y1="{score_y(0.0, top, highest)}" '
        f'x2="{LABEL_WIDTH + PLOT_WIDTH}" y2="{score_y(0.0, top, highest)}" stroke="#cccccc"/>',
        '<g class="score">',
    ]
    previous: float | None = None
    for index, (when, value) in enumerate(score):
        until = score[index + 1][0] if index + 1 < len(score) else span
        x, y = _x(when, scale), score_y(value, top, highest)
        if previous is not None:
            out.append(f'<line x1="{x}" y1="{previous}" x2="{x}" y2="{y}" {style}/>')
        out.append(f'<line x1="{x}" y1="{y}" x2="{_x(until, scale)}" y2="{y}" {style}/>')
        previous = y
    out.append("</g>")
    return out


def _overlay_legend(y: float) -> list[str]:
    items = [
        (OUTAGE, "link down"),
        *((colour, f"operator {kind}") for kind, colour in MARK_COLOURS.items()),
        (SCORE, "score"),
    ]
    out = []
    x = float(LABEL_WIDTH)
    for colour, text in items:
        out.append(f'<rect x="{x}" y="{y - 10}" width="14" height="12" fill="{colour}"/>')
        out.append(f'<text x="{x + 20}" y="{y}">{escape(text)}</text>')
        x += 40 + len(text) * CHAR_WIDTH
    return out


def _axis(span: float, scale: float, y: float) -> list[str]:
    step = _tick_step(span)
    out = [
        f'<line x1="{LABEL_WIDTH}" y1="{y}" x2="{LABEL_WIDTH + PLOT_WIDTH}" y2="{y}" '
        f'stroke="{INK}"/>'
    ]
    for index in range(int(span / step + 1e-9) + 1):
        seconds = index * step
        x = _x(seconds, scale)
        text = f"{seconds:g}"
        out.append(f'<line x1="{x}" y1="{y}" x2="{x}" y2="{y + 5}" stroke="{INK}"/>')
        out.append(f'<text x="{x}" y="{y + 18}" text-anchor="middle">{text}</text>')
    out.append(
        f'<text x="{LABEL_WIDTH + PLOT_WIDTH / 2}" y="{y + 34}" text-anchor="middle">'
        "seconds since the recording started</text>"
    )
    return out


def _tick_step(span: float) -> float:
    """A 1-2-5 step that gives about ten ticks over ``span`` seconds."""
    raw = span / 10
    magnitude = 10 ** math.floor(math.log10(raw))
    for factor in (1, 2, 5, 10):
        if raw <= factor * magnitude:
            return float(factor * magnitude)
    return float(10 * magnitude)  # pragma: no cover


def _legend(y: float) -> list[str]:
    items = (
        (TEAL, "", "running / success"),
        (RED, "", "failure"),
        (OLIVE, "", "waiting at a barrier"),
        (GREY, "", "paused"),
        ("white", f'stroke="{INK}" stroke-dasharray="4 2"', "stopped / unfinished"),
    )
    out = []
    x = float(LABEL_WIDTH)
    for colour, stroke, text in items:
        out.append(f'<rect x="{x}" y="{y - 10}" width="14" height="12" fill="{colour}" {stroke}/>')
        out.append(f'<text x="{x + 20}" y="{y}">{escape(text)}</text>')
        x += 40 + len(text) * CHAR_WIDTH
    out.append(
        f'<line x1="{x}" y1="{y - 12}" x2="{x}" y2="{y + 2}" stroke="{INK}" stroke-width="2"/>'
    )
    out.append(f'<text x="{x + 8}" y="{y}">barrier release</text>')
    return out
