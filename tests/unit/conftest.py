"""Fixtures for the mission-core unit tests: libraries, a deterministic mission, helpers.

The helpers are fixtures (not importable functions) because pytest runs with
``--import-mode=importlib``, where test modules cannot import each other.
"""

from __future__ import annotations

import copy
import itertools
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from rosmc_server.core import (
    EventKind,
    Library,
    Mission,
    MissionEvent,
    RosmcError,
    SkillStatus,
    load_library,
    mission_to_dict,
)
from rosmc_server.core.skills.library import library_from_dict

REPO = Path(__file__).resolve().parents[2]
SHIPPED_LIBRARY = REPO / "rosmc_server" / "config" / "mars_team.yaml"

# A small team: three identical walkers and one static base station. Every
# parameter type, bound, choice and marker type appears at least once.
TEST_LIBRARY: dict[str, Any] = {
    "rosmc_library": 1,
    "name": "unit_team",
    "models": {
        "walker": {
            "description": "A test robot.",
            "skills": {
                "move": {
                    "duration": 5,
                    "parameters": {
                        "target": {
                            "type": "pose",
                            "default": {"x": 0.0, "y": 0.0},
                            "marker": "pose",
                        },
                        "speed": {
                            "type": "float",
                            "default": 1.0,
                            "min": 0.1,
                            "max": 2.0,
                            "unit": "m/s",
                        },
                    },
                },
                "scan": {
                    "parameters": {
                        "area": {
                            "type": "list",
                            "default": [{"x": 0, "y": 0}, {"x": 1, "y": 0}, {"x": 0, "y": 1}],
                            "marker": "area",
                        },
                        "point": {"type": "pose", "default": {}, "marker": "position"},
                        "mode": {"type": "string", "default": "fast", "choices": ["fast", "slow"]},
                        "passes": {"type": "int", "default": 1, "min": 1, "max": 5},
                    },
                },
                "wait": {
                    "parameters": {
                        "seconds": {"type": "int", "default": 0, "min": 0},
                        "verbose": {"type": "bool", "default": False},
                        "note": {"type": "string", "default": ""},
                        "options": {"type": "dict", "default": {}},
                    },
                },
                "noop": None,
            },
        },
        "station": {"skills": {}},
    },
    "agents": {
        "alpha": {"kind": "dynamic", "model": "walker"},
        "bravo": {"kind": "dynamic", "model": "walker"},
        "charlie": {"kind": "dynamic", "model": "walker"},
        "base": {"kind": "static", "model": "station"},
    },
}


class FakeClock:
    """A clock that stands still unless a test moves it."""

    def __init__(self, now: float = 1000.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


def counting_ids() -> Callable[[str], str]:
    """Deterministic ids ``<prefix>-<n>`` with one counter for all prefixes."""
    counter = itertools.count(1)
    return lambda prefix: f"{prefix}-{next(counter)}"


def make_mission(library: Library, **kwargs: Any) -> Mission:
    """A mission with deterministic ids and a fixed clock."""
    kwargs.setdefault("clock", FakeClock())
    kwargs.setdefault("new_id", counting_ids())
    return Mission(library, **kwargs)


def snapshot(mission: Mission) -> dict[str, Any]:
    """Everything a mission holds, as plain data (what a save would write)."""
    return mission_to_dict(mission.state.content(), mission.revision)


def check_one_sentence(message: str) -> None:
    """An operator-facing message: non-empty, one line."""
    assert message.strip(), "empty error message"
    assert "\n" not in message and "\r" not in message, f"multi-line message: {message!r}"


def assert_rejected(
    mission: Mission,
    error: type[RosmcError],
    operation: Callable[..., object],
    *args: Any,
    match: str | None = None,
    **kwargs: Any,
) -> RosmcError:
    """Call ``operation``; it must raise exactly ``error`` and leave ``mission`` unchanged."""
    before = copy.deepcopy(snapshot(mission))
    revision = mission.revision
    with pytest.raises(RosmcError) as caught:
        operation(*args, **kwargs)
    assert type(caught.value) is error, f"expected {error.__name__}, got {caught.value!r}"
    message = str(caught.value)
    check_one_sentence(message)
    if match is not None:
        assert match in message, f"{match!r} not in {message!r}"
    assert mission.revision == revision
    assert snapshot(mission) == before, "a rejected request changed the mission"
    return caught.value


def assert_accepted(
    mission: Mission,
    kind: EventKind,
    operation: Callable[..., MissionEvent],
    *args: Any,
    **kwargs: Any,
) -> MissionEvent:
    """Call ``operation``; it must return one event of ``kind`` and bump the revision by 1."""
    revision = mission.revision
    event = operation(*args, **kwargs)
    assert isinstance(event, MissionEvent)
    assert event.kind is kind, f"expected {kind.name}, got {event.kind.name}"
    assert mission.revision == revision + 1
    assert event.revision == mission.revision
    check_one_sentence(event.summary)
    return event


class Driver:
    """Short-hands that move a mission into the state a test needs."""

    def __init__(self, mission: Mission) -> None:
        self.mission = mission

    def add(
        self, agent: str, skill: str = "move", params: dict[str, Any] | None = None, **kwargs: Any
    ) -> str:
        """Add a skill; return its id."""
        event = self.mission.add_skill(agent, skill, params, **kwargs)
        return event.change.put_skills[0].skill.id

    def adds(self, agent: str, count: int, skill: str = "move") -> list[str]:
        """Append ``count`` skills; return their ids."""
        return [self.add(agent, skill) for _ in range(count)]

    def sync(self, agent: str, upto: str | None = None) -> list[str]:
        """Synchronize a prefix and let the robot confirm it; return the ids."""
        event = self.mission.synchronize(agent, upto)
        ids = [placed.skill.id for placed in event.change.put_skills]
        self.mission.confirm_synchronized(agent, ids)
        return ids

    def status(self, skill_id: str) -> SkillStatus:
        """The current status of a skill."""
        return self.mission.state.skill(skill_id).status

    def run(self, skill_id: str) -> None:
        """The robot starts the skill."""
        self.mission.report_status(skill_id, SkillStatus.RUNNING)

    def finish(self, skill_id: str, status: SkillStatus = SkillStatus.SUCCESS) -> None:
        """The robot starts (if needed) and finishes the skill."""
        if self.status(skill_id) is not SkillStatus.RUNNING:
            self.run(skill_id)
        self.mission.report_status(skill_id, status)

    def ids(self, agent: str) -> list[str]:
        """The skill ids of an agent's task, in order."""
        return [skill.id for skill in self.mission.state.task(agent)]


@pytest.fixture(scope="session")
def shipped_library() -> Library:
    """The Mars team library the product ships."""
    return load_library(SHIPPED_LIBRARY)


@pytest.fixture(scope="session")
def library() -> Library:
    """The small unit-test library."""
    return library_from_dict(copy.deepcopy(TEST_LIBRARY), "unit_team.yaml")


@pytest.fixture
def library_data() -> dict[str, Any]:
    """A fresh copy of the unit-test library's data, for tests that break it."""
    return copy.deepcopy(TEST_LIBRARY)


@pytest.fixture
def clock() -> FakeClock:
    """The mission's clock."""
    return FakeClock()


@pytest.fixture
def mission(library: Library, clock: FakeClock) -> Mission:
    """An empty mission over the unit-test library with deterministic ids."""
    return make_mission(library, clock=clock)


@pytest.fixture
def drv(mission: Mission) -> Driver:
    """A driver for the ``mission`` fixture."""
    return Driver(mission)


@pytest.fixture
def rejected() -> Callable[..., RosmcError]:
    """``rejected(mission, Error, fn, *args, match=..., **kw)``: see :func:`assert_rejected`."""
    return assert_rejected


@pytest.fixture
def accepted() -> Callable[..., MissionEvent]:
    """``accepted(mission, EventKind.X, fn, *args, **kw)``: see :func:`assert_accepted`."""
    return assert_accepted


@pytest.fixture
def snap() -> Callable[[Mission], dict[str, Any]]:
    """``snap(mission)``: the mission as plain data."""
    return snapshot


@pytest.fixture
def new_mission_factory(library: Library) -> Iterator[Callable[..., Mission]]:
    """Build further missions over the unit-test library."""
    yield lambda **kwargs: make_mission(library, **kwargs)
