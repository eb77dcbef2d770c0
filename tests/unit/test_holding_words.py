"""A held robot and barrier waits: the typed field, its journey, and the words everywhere."""

from __future__ import annotations

from rosmc_rviz_markers.core.icons import status_rows
from rosmc_server.core import AgentStatus, Library, Mission, SkillStatus
from rosmc_server.core.model.control import HoldCause
from rosmc_server.core.skills.policy import LostLinkKind, LostLinkPolicy
from rosmc_server.core.views.holding import (
    barrier_partners,
    hold_sentence,
    not_arrived,
    wait_sentence,
)
from rosmc_server.core.views.vocabulary import HOLD_WHERE, age_text
from rosmc_server.executor.core.lost_link import LostLinkGuard
from rosmc_server.executor.core.skills import Outcome, SkillBehavior, SkillContext, SkillType
from rosmc_server.text.plain import format_tasks
from tests.unit.conftest import make_mission


def test_a_reported_word_becomes_a_cause_and_an_unknown_one_none() -> None:
    assert HoldCause.of("return_point") is HoldCause.RETURN_POINT
    assert HoldCause.of("") is HoldCause.NONE
    assert HoldCause.of("a word of a newer robot") is HoldCause.NONE
    assert HOLD_WHERE[HoldCause.RETURN_POINT] == "at its lost-link return point"
    assert set(HOLD_WHERE) == set(HoldCause), "every cause has its words"


def test_ages_read_to_the_second() -> None:
    assert [age_text(s) for s in (0, 45.9, 92, 3600, 7530, -3)] == [
        "0 s",
        "45 s",
        "1 min 32 s",
        "1 h 0 min",
        "2 h 5 min",
        "0 s",
    ]


def test_the_hold_sentence_names_the_partners_and_says_contact() -> None:
    assert hold_sentence("r4", HoldCause.RETURN_POINT, ("r1", "r2"), True) == (
        "r4 holds at its lost-link return point \u2014 its barrier partners r1, r2 wait."
    )
    assert hold_sentence("r4", HoldCause.LOST_LINK, (), False) == (
        "r4 holds where it lost the link. It is out of contact: Resume r4 goes out once it "
        "is heard again."
    )
    assert wait_sentence(("r4",), "B2", 92.0) == "waits for r4 at barrier B2 since 1 min 32 s"
    assert wait_sentence((), "B2", -1.0) == "waits for its partners' confirmation at barrier B2"


def _mission(library: Library) -> tuple[Mission, str, str]:
    mission = make_mission(library)
    alpha = mission.add_skill("alpha", "wait").change.put_skills[0].skill.id
    bravo = mission.add_skill("bravo", "wait").change.put_skills[0].skill.id
    mission.add_barrier([alpha, bravo])
    for agent, skill in (("alpha", alpha), ("bravo", bravo)):
        mission.synchronize(agent)
        mission.confirm_synchronized(agent, [skill])
    return mission, alpha, bravo


def test_partners_and_arrivals_come_from_the_mission(library: Library) -> None:
    mission, alpha, bravo = _mission(library)
    mission.report_status(bravo, SkillStatus.SYNCWAITING)
    state = mission.state
    (barrier,) = state.barriers
    members = [state.skill(i) for i in barrier.skill_ids]
    assert barrier_partners(state.barriers, state.skill, "alpha") == ("bravo",)
    assert not_arrived(members, "bravo") == ("alpha",)
    assert not_arrived(members, "alpha") == ()  # bravo is there
    mission.report_status(alpha, SkillStatus.SYNCWAITING)
    members = [mission.state.skill(i) for i in barrier.skill_ids]
    assert not_arrived(members, "bravo") == ()
    mission.report_status(alpha, SkillStatus.PAUSED)  # alpha left the wait: not there
    members = [mission.state.skill(i) for i in barrier.skill_ids]
    assert not_arrived(members, "bravo") == ("alpha",)


def test_rosmc_status_says_the_hold_its_cure_and_the_partners_wait(library: Library) -> None:
    mission, alpha, bravo = _mission(library)
    mission.report_status(bravo, SkillStatus.SYNCWAITING)
    statuses = {
        "alpha": AgentStatus("alpha", link="up", hold=HoldCause.RETURN_POINT),
        "bravo": AgentStatus("bravo", link="up", current_skill=bravo, barrier_wait=92.0),
    }
    text = format_tasks(mission.state, statuses=statuses)
    barrier_id = mission.state.barriers[0].id
    assert (
        "HOLDING: alpha holds at its lost-link return point \u2014 its barrier partners bravo "
        "wait. Free it: rosmc resume alpha"
    ) in text
    assert f"bravo waits for alpha at barrier {barrier_id} since 1 min 32 s" in text
    assert "HOLDING" not in format_tasks(mission.state, statuses={"alpha": AgentStatus(alpha)})


def test_rviz_labels_say_holding_and_the_wait_with_its_age() -> None:
    held = AgentStatus("r4", link="up", current_skill="s1", hold=HoldCause.RETURN_POINT)
    assert status_rows(held, agent="r4")[0].text == "r4: holding \u2014 Resume from its menu"
    waiting = AgentStatus(
        "r1",
        link="up",
        current_skill="s2",
        current_status=SkillStatus.SYNCWAITING,
        waiting_on="r4 at B2",
        barrier_wait=92.0,
    )
    assert status_rows(waiting, "meet", "r1")[0].text == (
        "r1: meet .. waiting on r4 at B2 since 1 min 32 s"
    )


class _Return(SkillBehavior):
    """A return skill that arrives on the second update."""

    def __init__(self) -> None:
        self.updates = 0

    def start(self, ctx: SkillContext) -> None:
        self.ctx = ctx

    def update(self, now: float) -> Outcome | None:
        self.updates += 1
        return Outcome.ok() if self.updates > 1 else None


def test_the_guard_says_why_it_holds_and_forgets_it_when_started_again() -> None:
    now = [0.0]
    types = {"go": SkillType("go", _Return)}
    guard = LostLinkGuard("r4", lambda: now[0], types)
    guard.adopt(LostLinkPolicy(LostLinkKind.SAFE_SKILL, 5.0, "go"), default=False)
    now[0] = 10.0
    assert guard.due(idle=False)
    guard.trigger(False, lambda _why: None)
    assert guard.held is HoldCause.NONE  # on its way: not holding yet
    assert not guard.step(now[0]) and guard.step(now[0])
    assert guard.held is HoldCause.SAFE_SKILL
    guard.operator_took_over()
    assert guard.held is HoldCause.NONE
