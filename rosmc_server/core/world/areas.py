"""Area (region of interest) polygons: validation, vertex drags, the default square.

An area is a simple polygon: no two edges cross, every edge at least :data:`MIN_SIDE`
long and the enclosed area at least :data:`MIN_AREA`. A drag that would break this is
refused (the marker snaps back) rather than repaired silently.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..errors import InvalidRequest

XY = tuple[float, float]
MIN_SIDE = 1.0  # metres
MIN_AREA = 1.0  # square metres
DEFAULT_SIDE = 8.0


def signed_area(vertices: Sequence[XY]) -> float:
    """The shoelace area: positive for counter-clockwise vertices."""
    total = 0.0
    for i, (x0, y0) in enumerate(vertices):
        x1, y1 = vertices[(i + 1) % len(vertices)]
        total += x0 * y1 - x1 * y0
    return total / 2.0


def centroid(vertices: Sequence[XY]) -> XY:
    """The mean of the vertices (what the server uses as an area's pose)."""
    return (
        sum(x for x, _ in vertices) / len(vertices),
        sum(y for _, y in vertices) / len(vertices),
    )


def _orientation(a: XY, b: XY, c: XY) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def segments_cross(a: XY, b: XY, c: XY, d: XY) -> bool:
    """Whether segment a-b and segment c-d intersect (touching counts)."""
    d1, d2 = _orientation(c, d, a), _orientation(c, d, b)
    d3, d4 = _orientation(a, b, c), _orientation(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0 not in (d1, d2, d3, d4):
        return True

    def on_segment(p: XY, q: XY, r: XY) -> bool:
        return min(p[0], q[0]) <= r[0] <= max(p[0], q[0]) and min(p[1], q[1]) <= r[1] <= max(
            p[1], q[1]
        )

    return (
        (d1 == 0 and on_segment(c, d, a))
        or (d2 == 0 and on_segment(c, d, b))
        or (d3 == 0 and on_segment(a, b, c))
        or (d4 == 0 and on_segment(a, b, d))
    )


def self_crossing(vertices: Sequence[XY]) -> bool:
    """Whether two non-adjacent edges of the closed polygon intersect."""
    n = len(vertices)
    edges = [(vertices[i], vertices[(i + 1) % n]) for i in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue  # neighbours share a vertex
            if segments_cross(*edges[i], *edges[j]):
                return True
    return False


def check_area(vertices: Sequence[XY], name: str = "the area") -> None:
    """Raise InvalidRequest unless ``vertices`` make a valid area polygon."""
    if len(vertices) < 3:
        raise InvalidRequest(f"{name} needs at least 3 vertices")
    if not all(math.isfinite(v) for xy in vertices for v in xy):
        raise InvalidRequest(f"{name} has a vertex that is not a finite number")
    n = len(vertices)
    for i in range(n):
        (x0, y0), (x1, y1) = vertices[i], vertices[(i + 1) % n]
        if math.hypot(x1 - x0, y1 - y0) < MIN_SIDE:
            raise InvalidRequest(f"{name} would have a side shorter than {MIN_SIDE:g} m")
    if self_crossing(vertices):
        raise InvalidRequest(f"{name} would cross itself")
    if abs(signed_area(vertices)) < MIN_AREA:
        raise InvalidRequest(f"{name} would be smaller than {MIN_AREA:g} m²")


def square(cx: float, cy: float, yaw: float = 0.0, side: float = DEFAULT_SIDE) -> tuple[XY, ...]:
    """A square of ``side`` centred at (cx, cy), edges along ``yaw``, counter-clockwise."""
    half = side / 2
    cos, sin = math.cos(yaw), math.sin(yaw)
    corners = ((-half, -half), (half, -half), (half, half), (-half, half))
    return tuple((cx + x * cos - y * sin, cy + x * sin + y * cos) for x, y in corners)


def move_vertex(vertices: Sequence[XY], index: int, x: float, y: float) -> tuple[XY, ...]:
    """The polygon with vertex ``index`` at (x, y), checked; InvalidRequest if invalid."""
    if not 0 <= index < len(vertices):
        raise InvalidRequest(f"the area has no vertex {index}")
    moved = tuple((x, y) if i == index else v for i, v in enumerate(vertices))
    check_area(moved)
    return moved


def translate(vertices: Sequence[XY], dx: float, dy: float) -> tuple[XY, ...]:
    """The polygon moved by (dx, dy)."""
    return tuple((x + dx, y + dy) for x, y in vertices)


def triangulate(vertices: Sequence[XY]) -> list[tuple[XY, XY, XY]]:
    """Triangles covering a simple polygon (ear clipping; a fan if that fails)."""
    points = list(vertices)
    if signed_area(points) < 0:
        points.reverse()
    index = list(range(len(points)))
    triangles: list[tuple[XY, XY, XY]] = []
    guard = 0
    while len(index) > 3 and guard < 4 * len(points):
        guard += 1
        for k in range(len(index)):
            a, b, c = (points[index[(k + o) % len(index)]] for o in (-1, 0, 1))
            if _orientation(a, b, c) <= 0:
                continue  # reflex corner
            others = (points[i] for i in index if points[i] not in (a, b, c))
            if any(_inside(p, a, b, c) for p in others):
                continue
            triangles.append((a, b, c))
            del index[k]
            break
        else:
            break
    if len(index) == 3:
        a, b, c = (points[i] for i in index)
        triangles.append((a, b, c))
        return triangles
    return [(points[0], points[i], points[i + 1]) for i in range(1, len(points) - 1)]


def _inside(p: XY, a: XY, b: XY, c: XY) -> bool:
    return _orientation(a, b, p) >= 0 and _orientation(b, c, p) >= 0 and _orientation(c, a, p) >= 0
