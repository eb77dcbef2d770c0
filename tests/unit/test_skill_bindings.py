"""Bindings in a library are checked when read; implementations are fitted to the library."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from rosmc_server.core import LibraryError, ParamType, SkillSetupError, SkillSpec
from rosmc_server.core.skills.bindings import BindingKind, BindingSpec, FieldSource
from rosmc_server.core.skills.library import library_from_dict, load_library
from rosmc_server.executor.basic_skills import Wait, skill_types
from rosmc_server.executor.core import SkillType
from rosmc_server.executor.core.fitting import fit_to_library

REPO = Path(__file__).resolve().parents[2]
LAB = REPO / "tests" / "data" / "lab_team.yaml"
TEST_TEAM = REPO / "tests" / "data" / "test_team.yaml"


def library_with(binding: object, extra: dict[str, Any] | None = None) -> dict[str, Any]:
    skill = {
        "parameters": {
            "target": {"type": "int", "default": 1},
            "label": {"type": "string", "default": "x"},
        },
        "binding": binding,
        **(extra or {}),
    }
    return {
        "rosmc_library": 1,
        "name": "lab",
        "models": {"lab_robot": {"skills": {"count_to": skill}}},
        "agents": {"lab1": {"kind": "dynamic", "model": "lab_robot"}},
    }


def test_the_lab_library_reads_its_bindings() -> None:
    skills = load_library(LAB).skills_of("lab1")
    assert skills["count_to"].binding == BindingSpec(
        BindingKind.ACTION,
        "/lab/count",
        "actionlib/Test",
        (FieldSource("goal", parameter="target"),),
        status="counted {feedback}",
        outcome="reached {result}",
    )
    topic = skills["point_at"].binding
    assert topic is not None and topic.fields[1] == FieldSource("header.frame_id", constant="map")
    assert skills["wait"].binding is None


ACTION = {"action": "/count", "type": "actionlib/Test"}


@pytest.mark.parametrize(
    ("binding", "problem"),
    [
        ({"type": "actionlib/Test"}, "binding: give exactly one of action, service or topic"),
        ({**ACTION, "topic": "/x"}, "binding: give exactly one of action, service or topic"),
        ({**ACTION, "type": "Test"}, "binding.type: must be package/Name, got 'Test'"),
        (
            {**ACTION, "fields": {"goal": "steps"}},
            "binding.fields.goal: names no parameter of the skill ('steps'; it has: target, label)",
        ),
        ({**ACTION, "fields": {"goal[0]": "target"}}, "'goal[0]' is no field path"),
        ({**ACTION, "status": "at {feedback[0]}"}, "'{feedback[0]}' names no message field"),
        ({**ACTION, "outcome": "at {"}, "binding.outcome: Single '{' encountered"),
        (
            {"topic": "/x", "type": "std_msgs/Int32", "success": "ok"},
            "binding.success: a topic has no result: the skill succeeds once sent",
        ),
        (
            {"service": "/x", "type": "std_srvs/SetBool", "status": "{message}"},
            "binding.status: only an action has feedback to show as status text",
        ),
        ({**ACTION, "wait": 3}, "binding: has unknown keys wait"),
    ],
)
def test_a_malformed_binding_is_refused_with_its_key(binding: object, problem: str) -> None:
    with pytest.raises(LibraryError) as caught:
        library_from_dict(library_with(binding), "lab.yaml")
    message = str(caught.value)
    assert message.startswith("lab.yaml: models.lab_robot.skills.count_to."), message
    assert problem in message, message


def test_implementations_take_the_library_parameters() -> None:
    fitted = fit_to_library(
        load_library(TEST_TEAM), "r1", {t.name: t for t in skill_types()}, _no_binding
    )
    assert fitted.types["count"].parameters == {"steps": ParamType.INT, "period": ParamType.FLOAT}
    assert fitted.types["count"].check({"steps": 2.5, "period": 1.0}) == (
        "parameter 'steps' of skill 'count' must be int"
    )
    assert fitted.unimplemented == ("teleport",)


def _no_binding(spec: SkillSpec) -> SkillType:
    raise AssertionError(f"{spec.name} has no binding")


@pytest.mark.parametrize(
    ("declared", "problem"),
    [
        (
            {"duration": ParamType.INT},
            "the implementation of skill 'wait' reads parameter 'duration' as int, but the "
            "library declares it float",
        ),
        (
            {"seconds": ParamType.FLOAT},
            "the implementation of skill 'wait' reads parameter 'seconds', which the library "
            "does not declare (it declares: duration)",
        ),
    ],
)
def test_an_implementation_that_disagrees_with_the_library_is_refused(
    declared: dict[str, ParamType], problem: str
) -> None:
    wait = SkillType("wait", Wait, declared)
    with pytest.raises(SkillSetupError) as caught:
        fit_to_library(load_library(TEST_TEAM), "r1", {"wait": wait}, _no_binding)
    assert str(caught.value) == problem


def test_a_bound_skill_comes_from_the_binding_and_may_not_be_implemented_too() -> None:
    library = load_library(LAB)
    made: list[str] = []

    def bind(spec: SkillSpec) -> SkillType:
        made.append(spec.name)
        return SkillType(spec.name, Wait)

    fitted = fit_to_library(library, "lab1", {t.name: t for t in skill_types()}, bind)
    assert sorted(made) == ["count_to", "point_at", "switch"]
    assert sorted(fitted.types) == ["count_to", "point_at", "switch", "wait"]
    assert fitted.unlisted == ("count", "probe")
    with pytest.raises(SkillSetupError) as caught:
        fit_to_library(library, "lab1", {"switch": SkillType("switch", Wait)}, bind)
    assert str(caught.value) == (
        "skill 'switch' is bound to service /lab/switch (std_srvs/SetBool) in library "
        "'lab_team' and implemented in code too: keep one of them"
    )


@pytest.mark.parametrize(
    ("agent", "problem"),
    [
        ("r9", "library 'lab_team': there is no agent 'r9'"),
        ("base", "'base' is a static agent in library 'lab_team'"),
    ],
)
def test_an_executor_for_no_robot_of_the_library_is_refused(agent: str, problem: str) -> None:
    with pytest.raises(SkillSetupError) as caught:
        fit_to_library(load_library(LAB), agent, {}, _no_binding)
    assert str(caught.value).startswith(problem)
