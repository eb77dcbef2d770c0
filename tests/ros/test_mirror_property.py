"""Property: a client mirroring the event stream always ends equal to the server's snapshot.

The mission state machine of ``tests/unit/test_properties.py`` drives a real
:class:`Mission` with random requests and robot reports. Every accepted event travels as
the server sends it — converted to ``rosmc/MissionEvent`` and serialized, then read back —
and reaches a :class:`MissionMirror` late, twice, out of order or not at all; snapshots it
asks for are answered (as ``rosmc/Mission`` messages) at a random later moment, when the
mission may have moved on. After every step, once what is in flight has arrived, the mirror
equals the mission, and so does a view kept only from the mirror's typed changes.
"""

from __future__ import annotations

import io
from typing import Any

import rosmc.msg as wire
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import invariant, rule

from rosmc_server.conversions import (
    event_from_msg,
    event_to_msg,
    mission_from_msg,
    mission_to_msg,
)
from rosmc_server.core import MissionEvent, MissionState
from rosmc_server.core.live.mirror import MissionMirror
from tests.unit.test_mirror import View
from tests.unit.test_properties import MissionMachine


def through_the_wire(msg: Any, message_class: Any) -> Any:
    buffer = io.BytesIO()
    msg.serialize(buffer)
    return message_class().deserialize(buffer.getvalue())


class MirroredMission(MissionMachine):
    """The mission machine, with a client mirror fed over an unreliable stream."""

    def __init__(self) -> None:
        super().__init__()
        self.snapshot_wanted = False
        self.mirror = MissionMirror(self._want_snapshot)
        self.view = View()
        self.mirror.subscribe(self.view)
        self.in_flight: list[MissionEvent] = []
        self.history = {self.mission.revision: self.mission.state.content()}
        self.mirror.start()

    def _want_snapshot(self) -> None:
        assert not self.snapshot_wanted, "a second snapshot request before the first answer"
        self.snapshot_wanted = True

    def attempt(self, name: str, *args: Any, **kwargs: Any) -> MissionEvent | None:
        event = super().attempt(name, *args, **kwargs)
        if event is not None:
            state = self.mission.state
            msg = event_to_msg(event, lambda skill_id: state.locate(skill_id)[0])
            self.in_flight.append(event_from_msg(through_the_wire(msg, wire.MissionEvent)))
            self.history[event.revision] = state.content()
        return event

    def answer_snapshot(self) -> None:
        content, revision = self.mission.state.content(), self.mission.revision
        msg = through_the_wire(mission_to_msg(content, revision, 0.0), wire.Mission)
        self.snapshot_wanted = False
        self.mirror.on_snapshot(MissionState(*mission_from_msg(msg)))

    @rule(data=st.data())
    def deliver_unreliably(self, data: Any) -> None:
        """Some of what is in flight arrives: shuffled, duplicated or lost."""
        if not self.in_flight:
            return
        count = data.draw(st.integers(1, len(self.in_flight)))
        batch, self.in_flight = self.in_flight[:count], self.in_flight[count:]
        batch = data.draw(st.permutations(batch))
        for event in batch:
            fate = data.draw(st.sampled_from(["arrive", "arrive", "arrive", "twice", "lost"]))
            if fate != "lost":
                self.mirror.on_event(event)
            if fate == "twice":
                self.mirror.on_event(event)

    @rule()
    def snapshot_answers(self) -> None:
        if self.snapshot_wanted:
            self.answer_snapshot()

    @rule()
    def everything_arrives(self) -> None:
        """The stream catches up: then the mirror equals the mission exactly."""
        for event in self.in_flight:
            self.mirror.on_event(event)
        self.in_flight.clear()
        if self.snapshot_wanted:
            self.answer_snapshot()
        if self.mirror.revision != self.mission.revision:
            # The newest events were lost: nothing shows a gap until the next event.
            self.answer_snapshot()
        state = self.mirror.state
        assert state is not None and self.mirror.synced
        assert state.revision == self.mission.revision
        assert state.content() == self.mission.state.content()
        assert self.view.matches(self.mission.state)

    @invariant()
    def mirror_shows_a_true_past_revision(self) -> None:
        """Whatever has arrived, the mirror is the mission as it was at some revision."""
        state = self.mirror.state
        if state is None:
            return
        assert state.content() == self.history[state.revision]
        assert self.view.matches(state)

    def teardown(self) -> None:
        self.everything_arrives()
        super().teardown()


MirroredMission.TestCase.settings = settings(
    max_examples=40,
    stateful_step_count=30,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
TestMirroredMission = MirroredMission.TestCase
