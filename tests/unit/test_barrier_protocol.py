"""The barrier protocol under cuts: no member starts until every member knows all arrived.

Engines on one clock exchange signals through :class:`Radio`, which cuts robots off the
way ``ip link set down`` does: nothing from or to a cut robot arrives. The cases are
the ones docs/barriers.md lists: a cut before a member arrives, during the release,
after the release; a member restarted; a member that never returns.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from rosmc_server.core import SkillStatus
from rosmc_server.core.robots.commands import CommandKind as K
from rosmc_server.core.robots.protocol import Signal, SignalKind
from rosmc_server.executor.core.barriers import READY_LEASE, BarrierBoard
from tests.unit.test_executor_engine import Robot, Team, barrier_of, make_skill

S = SkillStatus


@dataclass
class Radio:
    """Delivers a team's signals, except from or to robots whose radio is cut."""

    team: Team
    cut: set[str] = field(default_factory=set)
    deaf: set[str] = field(default_factory=set)  # these hear nothing, but are heard
    _sent: dict[str, int] = field(default_factory=dict)

    def deliver(self) -> None:
        moving = True
        while moving:
            moving = False
            for agent, robot in self.team.robots.items():
                new = robot.out.signals[self._sent.get(agent, 0) :]
                self._sent[agent] = len(robot.out.signals)
                for signal in new:
                    moving = True
                    if agent in self.cut:
                        continue
                    for other, peer in self.team.robots.items():
                        if other != agent and other not in self.cut | self.deaf:
                            peer.engine.hear(signal)

    def run(self, seconds: float, step: float = 0.05) -> None:
        end = self.team.clock.now + seconds
        while self.team.clock.now < end - 1e-9:
            self.team.clock.now = min(end, self.team.clock.now + step)
            for robot in self.team.robots.values():
                robot.engine.tick()
            self.deliver()


def barrier_team(*durations: float) -> Team:
    """Robot ``ri`` runs ``ai`` (``durations[i-1]`` s), then ``bi``; every ``bi`` in barrier B."""
    agents = [f"r{i}" for i in range(1, len(durations) + 1)]
    team = Team(*agents)
    barrier = barrier_of(*((f"b{a[1:]}", a) for a in agents))
    for agent, duration in zip(agents, durations, strict=True):
        n = agent[1:]
        team[agent].upload(
            make_skill(f"a{n}", agent=agent, params={"duration": duration}),
            make_skill(f"b{n}", agent=agent),
            barriers=(barrier,),
        )
        team[agent].send(K.START)
    return team


def started(team: Team, agent: str) -> float:
    skill = team[agent].skill(f"b{agent[1:]}")
    return skill.started if skill.status is not S.SYNCWAITING else 0.0


def waiting(team: Team, *agents: str) -> bool:
    return all(team[a].status(f"b{a[1:]}") is S.SYNCWAITING for a in agents)


def test_a_member_cut_off_before_it_arrives_does_not_start_alone() -> None:
    team = barrier_team(1.0, 3.0)
    radio = Radio(team)
    radio.run(2.8)  # r1 waits at b1 since 1 s, r2 still runs a2
    radio.cut.add("r2")  # r2's radio is cut 0.2 s before it arrives
    radio.run(0.7)
    assert waiting(team, "r1", "r2")  # r2 had heard r1 arrive, but r1 never heard r2
    assert team["r2"].engine.snapshot().waiting_on == "r1 at B (arrived, not yet confirmed)"
    radio.run(19.5)
    assert waiting(team, "r1", "r2")
    assert team["r2"].engine.snapshot().waiting_on == "r1 at B"  # unheard for a lease
    radio.cut.clear()
    restored = team.clock.now
    radio.run(1.0)
    assert not waiting(team, "r1", "r2")
    starts = [started(team, "r1"), started(team, "r2")]
    assert min(starts) >= restored  # nobody started during the cut
    assert max(starts) - restored <= 0.5 + 0.05  # within one announcement after contact


def test_a_cut_of_every_radio_while_the_last_member_arrives_starts_nobody() -> None:
    team = barrier_team(1.0, 1.0, 2.0)
    radio = Radio(team)
    radio.run(1.9)  # r1, r2 wait; r3 arrives in 0.1 s
    radio.cut.update(team.robots)
    radio.run(30.0)
    assert waiting(team, "r1", "r2", "r3")
    radio.cut.clear()
    restored = team.clock.now
    radio.run(1.0)
    starts = [started(team, a) for a in ("r1", "r2", "r3")]
    assert min(starts) >= restored and max(starts) - min(starts) <= 0.5 + 0.05


def test_no_member_starts_on_readiness_it_cannot_confirm() -> None:
    """The old rule started r2 here: it had heard r1 ready, and was ready itself."""
    team = barrier_team(1.0, 2.0)
    radio = Radio(team)
    radio.run(1.5)
    radio.cut.add("r1")  # r1 hears nothing more, and is heard no more
    radio.run(1.0)
    assert waiting(team, "r2")
    assert team["r2"].engine.snapshot().waiting_on == "r1 at B (arrived, not yet confirmed)"


def test_a_partner_that_missed_the_release_starts_when_it_hears_anything() -> None:
    team = barrier_team(1.0, 2.0)
    radio = Radio(team)
    radio.run(1.9)
    radio.deaf.add("r2")  # r2 arrives and confirms; r1 starts on that, r2 misses RELEASED
    radio.run(0.2)
    assert started(team, "r1") and waiting(team, "r2")
    radio.deaf.clear()
    radio.cut.add("r2")
    radio.run(10.0)
    assert waiting(team, "r2")
    radio.cut.clear()
    restored = team.clock.now
    radio.run(0.6)  # r2's next announcement reaches r1, which answers RELEASED
    assert restored <= started(team, "r2") <= restored + 0.55


def test_a_member_keeps_the_barrier_it_released_with_its_own_skill() -> None:
    team = barrier_team(0.1, 0.1)
    Radio(team).run(0.5)
    assert not waiting(team, "r1", "r2")  # released together
    assert started(team, "r1") == started(team, "r2")
    assert team["r1"].engine.board.to_dict() == {"released": ["B"], "mine": {"B": "b1"}}


def test_the_wait_timeout_waits_a_lease_after_the_last_confirmation() -> None:
    team = Team("r1", "r2")
    barrier = barrier_of(("b1", "r1"), ("b2", "r2"))
    team["r1"].upload(make_skill("b1", agent="r1", timeout=2.0), barriers=(barrier,))
    team["r2"].upload(make_skill("b2", agent="r2"), barriers=(barrier,))
    radio = Radio(team, cut={"r2"})
    team["r1"].send(K.START)
    radio.run(1.9)
    # r2 arrives and is heard by r1, but r1's answers never reach r2 (one-way loss)
    team["r1"].engine.hear(Signal("r2", "B", "b2", SignalKind.READY, team.clock.now))
    radio.run(0.5)  # the 2 s timeout is due, but r1 said CONFIRMED just now
    assert waiting(team, "r1")
    radio.run(2 * READY_LEASE + 0.5)
    assert team["r1"].status("b1") is S.FAILURE
    # It gave up only once nobody could hold a fresh CONFIRMED of r1 any more.
    confirmed = [s.stamp for s in team["r1"].out.signals if s.kind is SignalKind.CONFIRMED]
    assert team["r1"].skill("b1").finished - max(confirmed) > READY_LEASE


def test_an_overtaken_signal_does_not_undo_a_newer_one() -> None:
    board = BarrierBoard("r1")
    barrier = barrier_of(("b1", "r1"), ("b2", "r2"))
    board.hear(Signal("r2", "B", "b2", SignalKind.WITHDRAWN, 5.0), now=10.0)
    board.hear(Signal("r2", "B", "b2", SignalKind.READY, 4.0), now=10.1)  # sent earlier
    assert board.not_arrived(barrier, 10.1) == ("r2",)
    later = 10.0 + READY_LEASE + 1.0  # once the newer one has lapsed, any signal counts
    board.hear(Signal("r2", "B", "b2", SignalKind.READY, 1.0), now=later)
    assert board.not_arrived(barrier, later) == ()


def test_a_restarted_member_learns_the_release_from_its_partner() -> None:
    team = barrier_team(0.1, 0.1)
    radio = Radio(team)
    radio.run(0.5)
    assert not waiting(team, "r1", "r2")
    fresh = Robot("r3", team.clock)  # a partner that restarted without its state
    board = team["r1"].engine.board
    answer = board.reply(Signal("r2", "B", "b2", SignalKind.READY, team.clock.now), team.clock.now)
    assert answer == Signal("r1", "B", "b1", SignalKind.RELEASED, team.clock.now)
    assert (
        board.reply(Signal("r2", "B", "b2", SignalKind.READY, team.clock.now), team.clock.now)
        is None
    )
    assert fresh.engine.board.to_dict() == {"released": [], "mine": {}}


def test_saved_barrier_state_reads_back_and_a_malformed_one_is_refused() -> None:
    board = BarrierBoard("r1")
    board.released("B", "b1")
    copy = BarrierBoard("r1")
    copy.load(board.to_dict())
    assert copy.to_dict() == board.to_dict()
    copy.load({"released": ["B"]})  # a state file written before "mine" existed
    assert copy.is_released(barrier_of(("b1", "r1"), ("b2", "r2")))
    with pytest.raises(ValueError, match="malformed"):
        copy.load({"released": "B"})
