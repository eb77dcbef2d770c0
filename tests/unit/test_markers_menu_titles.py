"""Every rviz menu says whose it is: its first entry names the object and what it is.

rviz opens an interactive marker's menu under the mouse with no title; among robots,
flags and labels close together the operator could not tell which object's menu opened.
Checked where the menus are built (:class:`Scene`); ``tests/integration/test_rviz_mouse.py``
opens one in real rviz.
"""

from __future__ import annotations

from pathlib import Path

from rosmc_rviz_markers.core.menus import SelectObject
from rosmc_rviz_markers.core.scene import Scene
from rosmc_rviz_markers.core.specs import MarkerSpec
from rosmc_server.core import (
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
MARKERS = (
    TaskMarker(
        "RSS North",
        MarkerType.AREA,
        Pose(0, 10),
        tuple(Pose(x, y) for x, y in ((-2, 8), (2, 8), (2, 12), (-2, 12))),
    ),
    TaskMarker("goal", MarkerType.POSE, Pose(5, 5)),
    TaskMarker("spot", MarkerType.POSITION, Pose(-5, 5)),
)


def first_entry(spec: MarkerSpec) -> tuple[str, object]:
    entry = spec.menu.entries[0]
    assert entry.id == 1 and entry.parent == 0
    return entry.title, spec.menu.actions[entry.id]


def state() -> MissionState:
    mission = MissionState(MissionContent.empty(LIBRARY))
    mission.apply(Change(put_markers=MARKERS))
    return mission


def test_each_menu_starts_with_the_object_it_belongs_to() -> None:
    scene, mission = Scene(LIBRARY), state()
    assert first_entry(scene.agent_spec("drone", mission, None)) == (
        "drone \u2014 robot",
        SelectObject(),
    )
    assert first_entry(scene.agent_spec("lander", mission, None))[0] == "lander \u2014 object"
    titles = {m.name: first_entry(scene.marker_specs(mission, m.name)[0])[0] for m in MARKERS}
    assert titles == {
        "RSS North": "RSS North \u2014 area",
        "goal": "goal \u2014 pose",
        "spot": "spot \u2014 position",
    }
    # the entries that do things follow, as before
    drone = scene.agent_spec("drone", mission, None)
    top = [e.title for e in drone.menu.entries if e.parent == 0]
    assert top == ["drone \u2014 robot", "Add skill", "Resume", "Undo my last change", "Redo"]


def test_a_replay_has_no_menus_and_so_no_titles() -> None:
    scene, mission = Scene(LIBRARY, read_only=True), state()
    assert not scene.agent_spec("drone", mission, None).menu.entries
    assert not scene.marker_specs(mission, "goal")[0].menu.entries


def test_a_flag_is_big_enough_to_hit() -> None:
    """The flag's ground disc, the widest part to grab, is 2 m across (it was 1.2 m)."""
    disc = max(
        (p for p in geometry.flag(geometry.Color(1, 1, 1)) if p.shape is geometry.Shape.CYLINDER),
        key=lambda p: p.scale[0],
    )
    assert disc.scale[0] >= 2.0 and disc.scale[1] >= 2.0
    assert geometry.FLAG_DISC / 2 < geometry.TURN_RADIUS - 1.0, "clear of the turning ring"
