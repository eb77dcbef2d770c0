"""Label layout in rviz: at a busy region no two labels write over each other.

The busy place of the user study: RSS A (16, 9) with two robots standing in it and three
task markers (a position, a pose and an area), and 20 robots gathered at one place.
Checked in the pure geometry core (:mod:`rosmc_rviz_markers.core.labels`) with the very
labels the marker node draws (task labels from :class:`Scene`, robots' status blocks).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from rosmc_rviz_markers.core import labels
from rosmc_rviz_markers.core.icons import block_label, icon_levels, status_rows
from rosmc_rviz_markers.core.labels import Box, Label, layout, overlapping
from rosmc_rviz_markers.core.scene import Scene
from rosmc_rviz_markers.core.specs import task_label
from rosmc_server.core import (
    AgentStatus,
    MarkerType,
    MissionContent,
    MissionState,
    Pose,
    TaskMarker,
    load_library,
)
from rosmc_server.core.model.changes import Change
from rosmc_server.core.views import geometry

LIBRARY = load_library(
    Path(__file__).resolve().parents[2] / "rosmc_server" / "config" / "mars_team.yaml"
)
RSS_A = (16.0, 9.0)
SQUARE = tuple(Pose(RSS_A[0] + x, RSS_A[1] + y) for x, y in ((-2, -2), (2, -2), (2, 2), (-2, 2)))
MARKERS = (
    TaskMarker("RSS A sample spot", MarkerType.POSITION, Pose(RSS_A[0] + 0.5, RSS_A[1] + 0.5)),
    TaskMarker("RSS A approach", MarkerType.POSE, Pose(RSS_A[0] - 1.0, RSS_A[1], yaw=0.7)),
    TaskMarker("RSS A survey", MarkerType.AREA, Pose(*RSS_A), SQUARE),
)
ROBOTS = {"science_rover": (15.0, 8.0, 0.0), "manipulator_rover": (17.0, 8.5, 0.0)}


def robot_blocks(
    robots: dict[str, tuple[float, float, float]], labels: tuple[Box, ...] = ()
) -> list[Label]:
    """The robots' status blocks as the node draws them (levels from icon_levels, clear of
    the task ``labels``)."""
    levels = icon_levels(dict(robots), fixed=labels)
    out = []
    for agent, point in robots.items():
        status = AgentStatus(agent, link="up", last_heard=0.5, battery=0.9, wifi_signal=-55.0)
        rows = status_rows(status, "navigate_to", agent)
        out.append(block_label(agent, point, levels[agent], rows))
    return out


def laid_out_boxes(scene: Scene, state: MissionState, blocks: list[Label]) -> list[Box]:
    boxes = [block.box() for block in blocks]
    for marker in state.markers:
        spec = scene.marker_specs(state, marker.name)[0]
        label = task_label(marker, spec.label)
        boxes.append(label.box(scene.label_south.get(marker.name, 0.0)))
    return boxes


def test_labels_at_a_busy_region_do_not_overlap() -> None:
    state = MissionState(MissionContent.empty(LIBRARY))
    state.apply(Change(put_markers=MARKERS))
    scene = Scene(LIBRARY)
    # as they would stand without a layout, the labels write over each other
    assert overlapping(laid_out_boxes(scene, state, robot_blocks(ROBOTS)))

    moved = scene.relayout(state)
    assert moved, "some labels had to move"
    # the task labels stay put; the robots' blocks keep clear of them
    blocks = robot_blocks(ROBOTS, scene.label_boxes)
    assert not overlapping(laid_out_boxes(scene, state, blocks))
    # and a second layout of the same scene moves nothing (no redraw without a change)
    assert scene.relayout(state) == set()
    assert scene.relayout(state, [m.name for m in MARKERS]) == set()


def test_robots_driving_by_move_no_task_label() -> None:
    """Robots' status blocks are laid out after the task labels: however robots stand,
    the labels' layout (and so every task marker) is the same."""
    state = MissionState(MissionContent.empty(LIBRARY))
    state.apply(Change(put_markers=MARKERS))
    scene = Scene(LIBRARY)
    scene.relayout(state)
    before = dict(scene.label_south)
    for dx in (-3.0, -1.0, 0.0, 1.5):
        robots = {a: (x + dx, y, z) for a, (x, y, z) in ROBOTS.items()}
        blocks = robot_blocks(robots, scene.label_boxes)
        assert not overlapping([b.box() for b in blocks] + list(scene.label_boxes))
    assert scene.relayout(state) == set() and scene.label_south == before


def test_a_changed_label_moves_only_the_labels_it_covers() -> None:
    """A column of ten labels: the top one grows; only labels it now covers move (here
    none: growing sideways at the top of a column clears the rest)."""
    column = tuple(TaskMarker(f"c{i}", MarkerType.POSITION, Pose(0.0, -0.5 * i)) for i in range(10))
    state = MissionState(MissionContent.empty(LIBRARY))
    state.apply(Change(put_markers=column))
    scene = Scene(LIBRARY)
    scene.relayout(state)
    before = dict(scene.label_south)
    moved_top = TaskMarker("c0", MarkerType.POSITION, Pose(0.0, 0.5))
    state.apply(Change(put_markers=(moved_top,)))
    moved = scene.relayout(state, ["c0"])
    assert moved <= {"c0"}
    assert {k: v for k, v in scene.label_south.items() if k != "c0"} == {
        k: v for k, v in before.items() if k != "c0"
    }
    assert not overlapping(list(scene.label_boxes))


@pytest.mark.parametrize("read_only", [False, True])
def test_the_label_drawn_is_where_the_layout_put_it(read_only: bool) -> None:
    state = MissionState(MissionContent.empty(LIBRARY))
    state.apply(Change(put_markers=MARKERS))
    scene = Scene(LIBRARY, read_only=read_only)
    scene.relayout(state)
    for marker in MARKERS:
        spec = scene.marker_specs(state, marker.name)[0]
        text = next(
            p for c in spec.controls for p in c.primitives if p.shape is geometry.Shape.TEXT
        )
        # the marker frame turns with a pose marker's heading; the label must not
        x, y = text.position[:2]
        yaw = spec.yaw
        map_x = marker.pose.x + x * math.cos(yaw) - y * math.sin(yaw)
        map_y = marker.pose.y + x * math.sin(yaw) + y * math.cos(yaw)
        expected = task_label(marker, spec.label, movable=not read_only)
        south = scene.label_south.get(marker.name, 0.0)
        assert math.isclose(map_x, expected.x, abs_tol=1e-9)
        assert math.isclose(map_y, expected.y - south, abs_tol=1e-9)


def test_a_pose_marker_that_cannot_turn_keeps_its_label_near() -> None:
    pose = MARKERS[1]
    turning, fixed = task_label(pose, "x"), task_label(pose, "x", movable=False)
    assert pose.pose.y - turning.y > geometry.TURN_RADIUS, "outside the turning ring"
    assert pose.pose.y - fixed.y < geometry.TURN_RADIUS / 2, "no ring: next to its flag"


def test_twenty_robots_together_keep_their_blocks_apart() -> None:
    robots = {f"rover_{i}": (i % 5 * 1.5, i // 5 * 1.5, 0.0) for i in range(20)}
    boxes = [block.box() for block in robot_blocks(robots)]
    assert not overlapping(boxes)


def test_layout_stacks_labels_south_and_only_as_far_as_needed() -> None:
    same = [Label(f"m{i}", 0.0, 0.0, 0.3, ("marker [unused]",), 0.5) for i in range(3)]
    apart = Label("far", 40.0, 0.0, 0.3, ("far away",), 0.5)
    south = layout([*same, apart])
    assert south["far"] == 0.0, "a label with room stays where it is"
    assert sorted(south[f"m{i}"] for i in range(3))[0] == 0.0
    assert len({south[f"m{i}"] for i in range(3)}) == 3, "one column, one row each"
    boxes = [label.box(south[label.key]) for label in (*same, apart)]
    assert not overlapping(boxes)
    # stacked tightly: each just clears the one above it
    tops = sorted((b.top for b in boxes[:3]), reverse=True)
    bottoms = sorted((b.bottom for b in boxes[:3]), reverse=True)
    assert all(math.isclose(bottoms[i] - tops[i + 1], labels.GAP, abs_tol=1e-9) for i in range(2))


def test_a_status_block_lifts_clear_of_a_task_label() -> None:
    label = task_label(MARKERS[0], "RSS A sample spot [blueprint]")
    robot = {"rover": (MARKERS[0].pose.x, label.y - 1.5, 0.0)}
    assert icon_levels(robot) == {"rover": 0}
    lifted = icon_levels(robot, fixed=[label.box()])["rover"]
    assert lifted > 0
    block = robot_blocks(robot, (label.box(),))[0]
    assert not block.box().overlaps(label.box())
