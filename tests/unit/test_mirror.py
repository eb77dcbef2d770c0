"""The client's mission mirror (rosmc_server.core.live.mirror) and the one event-apply path.

A real :class:`Mission` on the shipped library produces the events; the mirror is fed
them in order, out of order, twice, with gaps and with replaced missions, and must end
equal to the mission, asking for a snapshot exactly when it cannot go on without one.
A view kept only from the typed change callbacks must end equal to the mission too.
"""

from __future__ import annotations

import itertools
import random
from dataclasses import replace
from pathlib import Path

import pytest

from rosmc_server.core import (
    AgentStatus,
    EventKind,
    MarkerType,
    Mission,
    MissionEvent,
    MissionState,
    Pose,
    RuleViolation,
    SkillStatus,
    TaskMarker,
    load_library,
)
from rosmc_server.core.live.mirror import MissionMirror
from rosmc_server.core.live.updates import (
    AgentStatusChanged,
    BarrierPut,
    BarrierRemoved,
    MarkerPut,
    MarkerRemoved,
    MirrorUpdate,
    MissionReset,
    SkillAdded,
    SkillChanged,
    SkillRemoved,
    SkillsMoved,
    SnapshotNeeded,
    apply_event,
)
from rosmc_server.core.model.changes import Change, SkillMove, moves_between

REPO = Path(__file__).resolve().parents[2]
LIBRARY = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
AGENTS = LIBRARY.dynamic_agents


class View:
    """What a GUI keeps, built only from the mirror's typed changes."""

    def __init__(self) -> None:
        self.tasks: dict[str, list[str]] = {}
        self.skills: dict[str, object] = {}
        self.barriers: dict[str, tuple[str, ...]] = {}
        self.markers: dict[str, TaskMarker] = {}
        self.updates: list[MirrorUpdate] = []

    def __call__(self, update: MirrorUpdate) -> None:
        self.updates.append(update)
        for change in update.changes:
            self.apply(change)

    def apply(self, change: object) -> None:
        match change:
            case MissionReset(state):
                self.tasks = {a: [s.id for s in state.task(a)] for a in state.agents}
                self.skills = {s.id: s for s in state.skills()}
                self.barriers = {b.id: b.skill_ids for b in state.barriers}
                self.markers = {m.name: m for m in state.markers}
            case SkillAdded(skill, index):
                self.tasks[skill.agent].insert(index, skill.id)
                self.skills[skill.id] = skill
            case SkillChanged(old, new, index):
                assert self.skills[old.id] == old
                assert self.tasks[new.agent][index] == new.id
                self.skills[new.id] = new
            case SkillRemoved(skill, index):
                assert self.tasks[skill.agent].pop(index) == skill.id
                del self.skills[skill.id]
            case SkillsMoved(agent, moves):
                for move in moves:  # one after the other, each index as it is once moved
                    self.tasks[agent].remove(move.skill_id)
                    self.tasks[agent].insert(move.index, move.skill_id)
            case BarrierPut(old, new):
                assert self.barriers.get(new.id) == (old.skill_ids if old else None)
                self.barriers[new.id] = new.skill_ids
            case BarrierRemoved(barrier):
                del self.barriers[barrier.id]
            case MarkerPut(old, new):
                assert self.markers.get(new.name) == old
                self.markers[new.name] = new
            case MarkerRemoved(marker):
                assert self.markers.pop(marker.name) == marker
            case AgentStatusChanged():
                pass
            case _:
                raise AssertionError(f"unknown change {change!r}")

    def matches(self, state: MissionState) -> bool:
        return (
            self.tasks == {a: [s.id for s in state.task(a)] for a in state.agents}
            and self.skills == {s.id: s for s in state.skills()}
            and self.barriers == {b.id: b.skill_ids for b in state.barriers}
            and self.markers == {m.name: m for m in state.markers}
        )


def make_mission() -> Mission:
    counter = itertools.count(1)
    return Mission(LIBRARY, clock=lambda: 1.0, new_id=lambda prefix: f"{prefix}-{next(counter)}")


def snapshot_of(mission: Mission) -> MissionState:
    return MissionState(mission.state.content(), mission.revision)


def wire_form(event: MissionEvent) -> MissionEvent:
    """The event as it arrives from /rosmc/mission_events: a replacement carries no content."""
    if event.change.replacement is None:
        return event
    return replace(event, change=Change())


def busy_mission(mission: Mission) -> list[MissionEvent]:
    """Every kind of change a client must follow, from a real mission."""
    events = []
    add = mission.add_skill
    events.append(mission.add_marker(TaskMarker("site", MarkerType.POSE, Pose(3, 4))))
    events.append(add("drone", "take_off", {"altitude": 5.0}))
    events.append(add("drone", "navigate_to", bindings={"target": "site"}))
    events.append(add("science_rover", "navigate_to", bindings={"target": "site"}))
    events.append(add("science_rover", "explore"))
    drone = [s.id for s in mission.state.task("drone")]
    rover = [s.id for s in mission.state.task("science_rover")]
    events.append(mission.reorder("drone", list(reversed(drone))))
    events.append(mission.edit_skill(drone[0], {"altitude": 9.0}, label="up"))
    events.append(mission.add_barrier([drone[1], rover[0]]))
    events.append(mission.add_barrier([drone[0], rover[1]]))
    events.append(mission.delete_barrier(mission.state.barriers[-1].id))
    events.append(mission.move_marker("site", Pose(5, 6)))
    events.append(mission.rename_marker("site", "crater"))
    events.append(mission.synchronize("drone"))
    events.append(mission.confirm_synchronized("drone", [drone[1], drone[0]]))
    events.append(mission.report_status(drone[1], SkillStatus.RUNNING))
    events.append(mission.report_status(drone[1], SkillStatus.FAILURE))
    events.append(mission.retry(drone[1]))
    events.append(mission.delete_skills([rover[1]]))
    events.append(mission.add_marker(TaskMarker("", MarkerType.POSITION, Pose(1, 1))))
    events.append(mission.delete_marker(mission.state.markers[-1].name))
    return events


def test_apply_event_refuses_what_does_not_follow() -> None:
    mission = make_mission()
    event = mission.add_skill("drone", "land")
    state = MissionState(make_mission().state.content(), 0)
    with pytest.raises(RuleViolation, match="does not follow"):
        apply_event(state, replace(event, revision=2))
    apply_event(state, event)
    assert state.content() == mission.state.content() and state.revision == 1
    replaced = mission.new_mission()
    with pytest.raises(SnapshotNeeded, match="replaced the mission"):
        apply_event(state, wire_form(replaced))
    apply_event(state, replaced)  # a journal's replacement carries its content
    assert state.content() == mission.state.content()


def test_mirror_follows_every_kind_of_change_in_order() -> None:
    mission = make_mission()
    asked: list[int] = []
    mirror = MissionMirror(lambda: asked.append(1))
    view = View()
    mirror.subscribe(view)
    mirror.start()
    assert asked == [1] and mirror.state is None
    mirror.on_snapshot(snapshot_of(mission))
    for event in busy_mission(mission):
        mirror.on_event(wire_form(event))
        assert mirror.revision == event.revision
    assert mirror.state is not None and mirror.state.content() == mission.state.content()
    assert view.matches(mission.state)
    assert asked == [1], "no gap, no replacement: one snapshot only"
    kinds = {type(c) for u in view.updates for c in u.changes}
    assert kinds >= {MissionReset, SkillAdded, SkillChanged, SkillRemoved, SkillsMoved}
    assert kinds >= {BarrierPut, MarkerPut, MarkerRemoved}


def test_events_before_the_snapshot_are_held_and_duplicates_ignored() -> None:
    mission = make_mission()
    mirror = MissionMirror()
    view = View()
    mirror.subscribe(view)
    start = snapshot_of(mission)
    events = [wire_form(e) for e in busy_mission(mission)]
    # Events 1..5 arrive before a snapshot taken at revision 3 answers.
    for event in events[:5]:
        mirror.on_event(event)
    assert mirror.state is None
    for event in events[:3]:
        apply_event(start, event)
    mirror.on_snapshot(start)
    assert mirror.revision == 5
    for event in [*events[3:], *events[::-1]]:  # duplicates, then everything backwards
        mirror.on_event(event)
    assert mirror.state is not None and mirror.state.content() == mission.state.content()
    assert view.matches(mission.state)


def test_a_gap_asks_for_one_snapshot_and_the_mirror_catches_up() -> None:
    mission = make_mission()
    asked: list[int] = []
    mirror = MissionMirror(lambda: asked.append(mirror.revision or 0))
    view = View()
    mirror.subscribe(view)
    mirror.on_snapshot(snapshot_of(mission))
    events = [wire_form(e) for e in busy_mission(mission)]
    mirror.on_event(events[0])
    for event in events[2:6]:  # event 2 was lost
        mirror.on_event(event)
    assert asked == [1], "one request for the whole gap"
    assert mirror.revision == 1 and not mirror.synced
    middle = make_mission()
    busy_mission(middle)
    mirror.on_snapshot(snapshot_of(middle))  # the answer is newer than every held event
    for event in events[6:]:
        mirror.on_event(event)
    assert mirror.synced and mirror.state is not None
    assert mirror.state.content() == mission.state.content()
    assert view.matches(mission.state)


def test_a_replaced_mission_is_fetched_and_a_stale_answer_ignored() -> None:
    mission = make_mission()
    asked: list[int] = []
    mirror = MissionMirror(lambda: asked.append(1))
    view = View()
    mirror.subscribe(view)
    mirror.on_snapshot(snapshot_of(mission))
    mirror.on_event(mission.add_skill("drone", "take_off"))
    mirror.on_event(mission.add_marker(TaskMarker("a", MarkerType.POSITION, Pose(1, 2))))
    old = snapshot_of(mission)
    replaced = mission.new_mission(keep_markers=False)
    mirror.on_event(wire_form(replaced))
    after = mission.add_skill("drone", "land")
    mirror.on_event(after)
    assert len(asked) == 1 and mirror.revision == old.revision
    mirror.on_snapshot(old)  # an answer older than the mirror: ignored, asks again
    assert len(asked) == 2
    mirror.on_snapshot(snapshot_of(mission))
    assert mirror.state is not None and mirror.state.content() == mission.state.content()
    assert view.matches(mission.state)


def test_a_restarted_server_is_taken_whatever_its_revision() -> None:
    mission = make_mission()
    mirror = MissionMirror()
    mirror.on_snapshot(snapshot_of(mission))
    for event in busy_mission(mission):
        mirror.on_event(event)
    fresh = make_mission()
    fresh.add_skill("drone", "land")
    mirror.on_snapshot(snapshot_of(fresh))
    assert mirror.revision == mission.revision, "a late answer does not rewind the mirror"
    mirror.on_snapshot(snapshot_of(fresh), restarted=True)
    assert mirror.revision == 1 and mirror.state is not None
    assert mirror.state.content() == fresh.state.content()


def test_agent_statuses_are_reported_when_they_change() -> None:
    mirror = MissionMirror()
    view = View()
    mirror.subscribe(view)
    up = AgentStatus("drone", link="up", battery=0.5)
    mirror.on_agent_statuses({"drone": up})
    mirror.on_agent_statuses({"drone": up})
    mirror.on_agent_statuses({"drone": replace(up, battery=0.4)})
    changes = [c for u in view.updates for c in u.changes]
    assert changes == [
        AgentStatusChanged(None, up),
        AgentStatusChanged(up, replace(up, battery=0.4)),
    ]
    assert mirror.agent_status("drone") == replace(up, battery=0.4)
    assert mirror.agent_status("rover") is None


def test_only_news_is_reported_not_every_tick_of_the_link_clock() -> None:
    # The server publishes every robot's status twice a second. For 7 s: three robots heard
    # each time (last_heard 0.0..0.4 s), one out of contact since 10 s before, one never heard.
    mirror = MissionMirror()
    view = View()
    mirror.subscribe(view)
    for tick in range(14):
        heard = {
            agent: AgentStatus(agent, link="up", last_heard=0.1 * (tick % 5), battery=0.8)
            for agent in ("drone", "science_rover", "manipulator_rover")
        }
        lost = AgentStatus("box", link="down", last_heard=10.0 + 0.5 * tick, battery=0.3)
        mirror.on_agent_statuses({**heard, "box": lost, "lander": AgentStatus("lander")})
    changes = [c for u in view.updates for c in u.changes if isinstance(c, AgentStatusChanged)]
    first = {c.new.agent for c in changes if c.old is None}
    assert first == {"drone", "science_rover", "manipulator_rover", "box", "lander"}
    later = [c for c in changes if c.old is not None]
    # Only the robot out of contact, once per second of its outage (what "LINK DOWN 12 s"
    # shows): 10 s .. 16.5 s crosses 6 whole seconds.
    assert [c.new.agent for c in later] == ["box"] * 6
    assert [int(c.new.last_heard) for c in later] == [11, 12, 13, 14, 15, 16]
    assert len(changes) == 11  # before: 14 ticks x 4 robots with a changed age = 56 + 5
    # The mirror holds the latest status all the same, and a real change is news.
    assert mirror.agent_status("drone") == AgentStatus(
        "drone", link="up", last_heard=0.1 * (13 % 5), battery=0.8
    )
    drone = mirror.agent_status("drone")
    assert drone is not None
    mirror.on_agent_statuses({"drone": replace(drone, battery=0.79)})
    assert view.updates[-1].changes == (AgentStatusChanged(drone, replace(drone, battery=0.79)),)


def test_a_restarted_server_s_robots_start_unknown() -> None:
    mission = make_mission()
    mirror = MissionMirror()
    mirror.on_snapshot(snapshot_of(mission))
    up = AgentStatus("drone", link="up", battery=0.5)
    mirror.on_agent_statuses({"drone": up, "rover": AgentStatus("rover")})
    view = View()
    mirror.subscribe(view)
    mirror.on_snapshot(snapshot_of(mission))  # the same server again: nothing forgotten
    assert mirror.agent_status("drone") == up
    mirror.on_snapshot(snapshot_of(mission), restarted=True)
    statuses = [c for u in view.updates for c in u.changes if isinstance(c, AgentStatusChanged)]
    assert statuses == [AgentStatusChanged(up, AgentStatus("drone"))]
    assert mirror.agent_statuses == {}


def test_a_moved_replay_s_mission_is_taken_and_its_robots_stay() -> None:
    """A replay publishes the robots' states for its new time, then says it moved."""
    mission = make_mission()
    mirror = MissionMirror()
    mirror.on_snapshot(snapshot_of(mission))
    later = snapshot_of(mission)
    for event in busy_mission(mission):
        mirror.on_event(event)
    ahead = mirror.revision
    assert ahead is not None and ahead > later.revision
    up = AgentStatus("drone", link="up", battery=0.5)
    mirror.on_agent_statuses({"drone": up})
    mirror.on_snapshot(later, moved=True)  # back in time: an older revision, taken
    assert mirror.revision == later.revision
    assert mirror.agent_statuses == {"drone": up}


def test_a_late_listener_starts_from_the_current_mission_and_can_leave() -> None:
    mission = make_mission()
    mirror = MissionMirror()
    mirror.on_snapshot(snapshot_of(mission))
    for event in busy_mission(mission):
        mirror.on_event(event)
    view = View()
    unsubscribe = mirror.subscribe(view)
    assert view.matches(mission.state) and len(view.updates) == 1
    unsubscribe()
    mirror.on_event(mission.add_skill("drone", "land"))
    assert len(view.updates) == 1


def test_a_failing_listener_does_not_stop_the_others() -> None:
    mission = make_mission()
    mirror = MissionMirror()

    def broken(update: MirrorUpdate) -> None:
        raise ValueError("broken view")

    mirror.subscribe(broken)
    view = View()
    mirror.subscribe(view)
    mirror.on_snapshot(snapshot_of(mission))
    mirror.on_event(mission.add_skill("drone", "land"))
    assert view.matches(mission.state)


def test_a_lost_last_event_is_noticed_from_the_servers_revision() -> None:
    mission = make_mission()
    asked: list[int] = []
    mirror = MissionMirror(lambda: asked.append(1))
    mirror.on_snapshot(snapshot_of(mission))
    mirror.on_event(mission.add_skill("drone", "land"))
    mission.add_skill("drone", "take_off")  # published, never arrives; nothing comes after it
    mirror.on_server_revision(2)  # the server's word may overtake an event in flight
    assert asked == []
    mirror.on_server_revision(2)  # by its next word, revision 2 should have arrived
    assert asked == [1]
    mirror.on_snapshot(snapshot_of(mission))
    assert mirror.revision == 2 and mirror.synced
    mirror.on_server_revision(2)
    mirror.on_server_revision(0)  # a server that started anew: its restart is seen elsewhere
    assert asked == [1]


# -- reorders travel as moves --------------------------------------------------------------
def test_reorders_reach_every_follower_as_the_server_has_them() -> None:
    """Moves and whole new orders, with barriers in the way: the server's order everywhere."""
    mission = make_mission()
    for agent in AGENTS:
        for _ in range(8):
            mission.add_skill(agent, "navigate_to")
    mission.synchronize("drone", mission.state.task("drone")[1].id)  # 2 skills uploading
    tasks = {a: [s.id for s in mission.state.task(a)] for a in AGENTS}
    mission.add_barrier([tasks["drone"][3], tasks["science_rover"][2]])
    mission.add_barrier(
        [tasks["drone"][6], tasks["science_rover"][5], tasks["manipulator_rover"][4]]
    )
    replayed = snapshot_of(mission)
    mirror = MissionMirror()
    view = View()
    mirror.subscribe(view)
    mirror.on_snapshot(snapshot_of(mission))
    rng = random.Random(12)
    accepted = refused = 0
    for step in range(80):
        agent = rng.choice(AGENTS)
        start = mission.state.sections(agent).editable_start
        ids = [s.id for s in mission.state.task(agent)[start:]]
        try:
            if step % 2:
                picks = rng.sample(ids, rng.randint(1, 3))
                moves = [SkillMove(s, rng.randrange(start, start + len(ids))) for s in picks]
                event = mission.move_skills(agent, moves)
            else:
                event = mission.reorder(agent, rng.sample(ids, len(ids)))
        except RuleViolation as error:
            assert "deadlock" in str(error)
            refused += 1
            continue
        accepted += 1
        assert not event.change.blueprint_order and len(event.change.moves) <= len(ids)
        apply_event(replayed, event)
        mirror.on_event(event)
        assert mirror.state is not None
        for follower in (replayed, mirror.state):
            assert [s.id for s in follower.task(agent)] == [s.id for s in mission.state.task(agent)]
    assert accepted > 20 and refused > 5, (accepted, refused)
    assert replayed.content() == mission.state.content()
    assert view.matches(mission.state)


def test_an_old_reorder_with_the_whole_order_still_applies() -> None:
    """Journals written before moves carry the agent's whole editable blueprint in order."""
    mission = make_mission()
    for _ in range(6):
        mission.add_skill("drone", "navigate_to")
    mission.synchronize("drone", mission.state.task("drone")[0].id)  # the first is uploading
    ids = [s.id for s in mission.state.task("drone")]
    new = [ids[4], ids[1], ids[5], ids[2], ids[3]]
    old = MissionEvent(
        mission.revision + 1,
        EventKind.SKILLS_REORDERED,
        "drone",
        "drone's blueprint reordered",
        2.0,
        Change(order_agent="drone", blueprint_order=tuple(new)),
    )
    state = snapshot_of(mission)
    apply_event(state, old)
    assert [s.id for s in state.task("drone")] == [ids[0], *new]
    mirror = MissionMirror()
    view = View()
    mirror.subscribe(view)
    mirror.on_snapshot(snapshot_of(mission))
    mirror.on_event(old)
    assert mirror.state is not None and mirror.state.content() == state.content()
    assert view.matches(state)
    (moved,) = view.updates[-1].changes
    assert isinstance(moved, SkillsMoved) and moved.moves == moves_between(ids[1:], new, 1)
    mission.replay(old)  # the server resuming from such a journal
    assert mission.state.content() == state.content()
