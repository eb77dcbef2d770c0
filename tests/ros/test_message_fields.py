"""Binding fields filled from parameters: each parameter type into the fields it fits."""

from __future__ import annotations

import math
import re

import pytest
from actionlib.msg import TestRequestGoal as RequestGoal
from geometry_msgs.msg import Polygon, PolygonStamped, Pose2D, PoseStamped
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import SetBoolResponse

from rosmc_server.core import ParamType, Pose, SkillSetupError
from rosmc_server.core.skills.bindings import FieldSource
from rosmc_server.executor.ros.message_fields import (
    MessageRecipe,
    Template,
    bool_field,
    message_class,
)

WHERE = "skill 'x'"


def fill(message: type, field: str, ptype: ParamType, value: object) -> object:
    recipe = MessageRecipe.make(message, (FieldSource(field, "p"),), {"p": ptype}, WHERE)
    return recipe.build({"p": value})  # type: ignore[dict-item]


def test_parameters_fill_the_fields_they_fit() -> None:
    goal = fill(RequestGoal, "the_result", ParamType.INT, 7)
    assert goal.the_result == 7  # type: ignore[attr-defined]
    goal = fill(RequestGoal, "delay_accept", ParamType.FLOAT, 1.5)
    assert goal.delay_accept.to_sec() == 1.5  # type: ignore[attr-defined]
    pose = fill(Pose2D, "theta", ParamType.FLOAT, 0.5)
    assert pose.theta == 0.5  # type: ignore[attr-defined]
    stamped = fill(PoseStamped, "pose", ParamType.POSE, Pose(1.0, 2.0, 3.0, yaw=math.pi))
    assert stamped.pose.position.x == 1.0  # type: ignore[attr-defined]
    assert stamped.pose.orientation.z == pytest.approx(1.0)  # type: ignore[attr-defined]
    array = fill(Float64MultiArray, "data", ParamType.LIST, [1.0, 2.5])
    assert list(array.data) == [1.0, 2.5]  # type: ignore[attr-defined]


def test_an_area_fills_a_polygon() -> None:
    area = [{"x": 0.0, "y": 0.0}, {"x": 4.0, "y": 0.0}, {"x": 4.0, "y": 3.0}]
    stamped = fill(PolygonStamped, "polygon", ParamType.LIST, area)
    assert isinstance(stamped.polygon, Polygon)  # type: ignore[attr-defined]
    assert [(p.x, p.y) for p in stamped.polygon.points]  # type: ignore[attr-defined] == [(0.0, 0.0), (4.0, 0.0), (4.0, 3.0)]


@pytest.mark.parametrize(
    ("field", "ptype", "problem"),
    [
        (
            "the_result",
            ParamType.STRING,
            "field 'the_result' of actionlib/TestRequestGoal is of type int32, which parameter 'p' "
            "(string) cannot fill",
        ),
        (
            "result_text.data",
            ParamType.STRING,
            "field 'result_text' is of type string, which has no fields",
        ),
        (
            "answer",
            ParamType.INT,
            "actionlib/TestRequestGoal has no field 'answer' (it has: terminate_status, "
            "ignore_cancel, result_text, the_result, is_simple_client, delay_accept, "
            "delay_terminate, pause_status)",
        ),
    ],
)
def test_a_field_no_parameter_fits_is_refused(field: str, ptype: ParamType, problem: str) -> None:
    with pytest.raises(SkillSetupError) as caught:
        MessageRecipe.make(RequestGoal, (FieldSource(field, "p"),), {"p": ptype}, WHERE)
    assert str(caught.value) == f"{WHERE}: {problem}"


def test_constants_types_templates_and_success_fields_are_checked() -> None:
    recipe = MessageRecipe.make(
        RequestGoal, (FieldSource("result_text", constant="ok"),), {}, WHERE
    )
    assert recipe.build({}).result_text == "ok"  # type: ignore[attr-defined]
    with pytest.raises(SkillSetupError, match="there is no message type nope/Nope on this robot"):
        message_class("nope/Nope", WHERE)
    text = Template.make("{message} ({success})", SetBoolResponse, WHERE)
    assert text.render(SetBoolResponse(True, "lit")) == "lit (True)"
    with pytest.raises(SkillSetupError, match=re.escape("the text '{message:d}' does not format")):
        Template.make("{message:d}", SetBoolResponse, WHERE)
    assert bool_field(SetBoolResponse, "success", WHERE) == "success"
    with pytest.raises(SkillSetupError, match="success field 'message' is no bool"):
        bool_field(SetBoolResponse, "message", WHERE)
