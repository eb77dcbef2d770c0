"""The operator's rules, once: what the GUIs enable is exactly what the server accepts.

Random missions (random operator requests and robot answers on a real
:class:`~rosmc_server.core.Mission`, many refused) are checked skill by skill and robot by
robot: an action is legal by :mod:`rosmc_server.core.rules.legality` exactly when the server's
operation on a copy of the mission is accepted; and the command GUI's legality over its
own view of the mission (built from mirror updates, as live) says the same. Reordering is
not covered: a move is offered whenever it has room, and the server may still refuse one
whose new order would make barriers deadlock (it says so in one sentence).
"""

from __future__ import annotations

import contextlib
import itertools
import random
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from rosmc_rqt_command.core.legality import legal_actions, legal_robot_actions
from rosmc_rqt_command.core.mission_view import MissionView
from rosmc_rqt_command.core.view_state import view_update
from rosmc_server.core import (
    AgentStatus,
    Library,
    Mission,
    MissionEvent,
    MissionState,
    RosmcError,
    SkillInstance,
    SkillStatus,
)
from rosmc_server.core.live.mirror import MissionMirror
from rosmc_server.core.live.updates import MirrorUpdate
from rosmc_server.core.model.control import ExecutorState
from rosmc_server.core.rules.legality import (
    RobotAction,
    SkillAction,
    StatePicture,
    TaskView,
    legal_skill_actions,
)
from rosmc_server.core.rules.legality import (
    legal_robot_actions as robot_rules,
)

S = SkillStatus
A = SkillAction
SEEDS = range(60)


def ids() -> Callable[[str], str]:
    counter = itertools.count(1)
    return lambda prefix: f"{prefix}-{next(counter)}"


def random_mission(library: Library, seed: int) -> Mission:
    """A mission after ~60 random requests and robot answers (refusals included)."""
    rng = random.Random(seed)
    mission = Mission(library, new_id=ids(), clock=lambda: 1.0)
    for _ in range(60):
        with contextlib.suppress(RosmcError):  # refused: the mission is unchanged
            random_step(mission, rng)
    return mission


def random_step(mission: Mission, rng: random.Random) -> MissionEvent | None:
    """One random operator request or robot answer (RosmcError if the mission refuses it)."""
    library = mission.library
    agent = rng.choice(list(library.dynamic_agents))
    task = list(mission.state.task(agent))
    some = rng.choice([None, *[s.id for s in task]])
    skills = [s.id for s in mission.state.skills()]
    step = rng.choice([0, 0, 1, 2, 2, 3, 4, 5, 5, 5, 5, 6, 6, 7, 8])
    if step == 0 or not skills:
        return mission.add_skill(agent, rng.choice(sorted(library.skills_of(agent))))
    if step == 1:
        return mission.synchronize(agent, some)
    if step == 2:
        return mission.confirm_synchronized(agent, _transferring(task))
    if step == 3:
        return mission.unsynchronize(agent, some)
    if step == 4:
        return mission.confirm_unsynchronized(agent, _transferring(task))
    if step == 5:
        return _report(mission, task, rng)
    if step == 6:
        return mission.add_barrier(rng.sample(skills, min(2, len(skills))))
    if step == 7:
        return mission.retry(rng.choice(skills))
    return mission.stop(agent)


def _transferring(task: list[SkillInstance]) -> list[str]:
    return [s.id for s in task if s.transfer.name != "NONE"]


def _report(mission: Mission, task: list[SkillInstance], rng: random.Random) -> MissionEvent | None:
    """The robot reports its next synchronized skill one step further, as robots do."""
    pending = [s for s in task if s.status in (S.IDLE_SYNCHRONIZED, S.RUNNING, S.PAUSED)]
    if not pending:
        return None
    skill = pending[0]
    if skill.status is S.RUNNING:
        status = rng.choice([S.SUCCESS, S.SUCCESS, S.FAILURE, S.PAUSED])
    else:
        status = (
            rng.choice([S.RUNNING, S.SYNCWAITING])
            if skill.status is S.IDLE_SYNCHRONIZED
            else S.RUNNING
        )
    return mission.report_status(skill.id, status)


def accepted(mission: Mission, operation: Callable[[Mission], Any]) -> bool:
    """The server accepts ``operation`` on a copy of ``mission``."""
    copy = Mission(mission.library, mission.state.content().copy(), mission.revision)
    try:
        operation(copy)
    except RosmcError:
        return False
    return True


def skill_operations(skill: SkillInstance, state: MissionState) -> Iterator[tuple[A, Any]]:
    """Each action on ``skill`` alone, with the server operation the GUI sends for it."""
    agent = skill.agent
    yield A.DELETE, lambda m: m.delete_skills([skill.id])
    yield A.SYNC, lambda m: m.synchronize(agent, skill.id)
    yield A.UNSYNC, lambda m: m.unsynchronize(agent, skill.id)
    yield A.RETRY, lambda m: m.retry(skill.id)
    yield A.SKIP, lambda m: m.skip(skill.id)
    barrier = state.barrier_of(skill.id)
    if barrier is not None:
        yield A.DELETE_BARRIER, lambda m: m.delete_barrier(barrier.id)


@pytest.mark.parametrize("seed", SEEDS)
def test_a_skill_action_is_legal_exactly_when_the_server_accepts_it(
    library: Library, seed: int
) -> None:
    mission = random_mission(library, seed)
    picture = StatePicture(mission.state)
    for skill in mission.state.skills():
        legal = legal_skill_actions(picture, [skill])
        for action, operation in skill_operations(skill, mission.state):
            assert (action in legal) == accepted(mission, operation), (action, skill)


@pytest.mark.parametrize("seed", SEEDS)
def test_a_barrier_is_offered_exactly_when_the_server_accepts_it(
    library: Library, seed: int
) -> None:
    mission = random_mission(library, seed)
    picture = StatePicture(mission.state)
    for first, second in itertools.combinations(list(mission.state.skills()), 2):
        legal = A.BARRIER in legal_skill_actions(picture, [first, second])
        pair = [first.id, second.id]
        assert legal == accepted(mission, lambda m: m.add_barrier(pair)), pair  # noqa: B023


@pytest.mark.parametrize("seed", SEEDS)
def test_a_robot_send_or_take_back_is_legal_exactly_when_accepted(
    library: Library, seed: int
) -> None:
    mission = random_mission(library, seed)
    for agent in mission.state.agents:
        legal = robot_rules(TaskView.of(mission.state, agent), ExecutorState.UNKNOWN)
        sync = accepted(mission, lambda m: m.synchronize(agent, None))  # noqa: B023
        unsync = accepted(mission, lambda m: m.unsynchronize(agent, None))  # noqa: B023
        assert (RobotAction.SYNC_ALL in legal) == sync, agent
        assert (RobotAction.UNSYNC_ALL in legal) == unsync, agent


def gui_view(mission: Mission) -> MissionView:
    """The command GUI's view of ``mission``, built from a mirror update as live."""
    view = MissionView()
    mirror = MissionMirror()

    def take(update: MirrorUpdate) -> None:
        view.apply(view_update(update, mirror.state))

    mirror.subscribe(take)
    mirror.on_snapshot(MissionState(mission.state.content(), mission.revision))
    return view


@pytest.mark.parametrize("seed", SEEDS)
def test_the_gui_greys_out_what_the_server_refuses(library: Library, seed: int) -> None:
    mission = random_mission(library, seed)
    picture = StatePicture(mission.state)
    view = gui_view(mission)
    skills = list(mission.state.skills())
    for selection in [*([s] for s in skills), *itertools.combinations(skills, 2)]:
        shown = view.skills([s.id for s in selection])
        assert legal_actions(view, shown) == legal_skill_actions(picture, list(selection))
    for agent in mission.state.agents:
        task = TaskView.of(mission.state, agent)
        assert legal_robot_actions(view, agent) == robot_rules(task, ExecutorState.UNKNOWN)


def test_random_missions_reach_the_interesting_states(library: Library) -> None:
    """The generator is worth its name: every status and both transfers occur."""
    statuses = set()
    transfers = set()
    barriers = 0
    for seed in SEEDS:
        state = random_mission(library, seed).state
        statuses |= {s.status for s in state.skills()}
        transfers |= {s.transfer.name for s in state.skills()}
        barriers += len(state.barriers)
    assert statuses >= {S.IDLE, S.IDLE_SYNCHRONIZED, S.RUNNING, S.SUCCESS, S.FAILURE}
    assert transfers >= {"NONE", "UPLOADING", "REMOVING"}
    assert barriers > 0


@pytest.mark.parametrize(
    ("word", "state", "started"),
    [
        ("", ExecutorState.UNKNOWN, False),
        ("stopped", ExecutorState.STOPPED, False),
        ("paused", ExecutorState.PAUSED, False),
        ("running", ExecutorState.RUNNING, True),
        ("holding", ExecutorState.HOLDING, True),
        ("contingency", ExecutorState.CONTINGENCY, True),
        ("dancing", ExecutorState.UNKNOWN, False),
    ],
)
def test_a_reported_executor_word_is_one_state(
    word: str, state: ExecutorState, started: bool
) -> None:
    status = AgentStatus("alpha", executor_state=word)
    assert status.executor is state
    assert state.started is started


def test_a_paused_robot_offers_resume_and_stop_only(library: Library) -> None:
    mission = Mission(library, new_id=ids(), clock=lambda: 1.0)
    agent = library.dynamic_agents[0]
    skill = sorted(library.skills_of(agent))[0]
    added = [mission.add_skill(agent, skill).change.put_skills[0].skill.id for _ in range(2)]
    mission.synchronize(agent, None)
    mission.confirm_synchronized(agent, added)
    mission.report_status(added[0], S.RUNNING)
    task = TaskView.of(mission.state, agent)
    assert robot_rules(task, ExecutorState.RUNNING) == {
        RobotAction.PAUSE,
        RobotAction.STOP,
        RobotAction.UNSYNC_ALL,
    }
    assert robot_rules(task, ExecutorState.PAUSED) == {
        RobotAction.RESUME,
        RobotAction.STOP,
        RobotAction.UNSYNC_ALL,
    }
    mission.stop(agent)
    stopped = TaskView.of(mission.state, agent)
    assert RobotAction.START in robot_rules(stopped, ExecutorState.STOPPED)
