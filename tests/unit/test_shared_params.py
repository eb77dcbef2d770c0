"""Skills of a mission file whose parameters are exactly alike share one checked dict.

:class:`~rosmc_server.core.files.shared_params.SharedParams` lets the mission reader check the
parameters of a skill once for every later skill of the same kind with the very same raw
values; values equal but of another type or sign are checked for themselves.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from rosmc_server.core import Library, MissionFileError
from rosmc_server.core.files.mission_reader import mission_from_dict

WAIT = {"seconds": 3, "verbose": True, "note": "n", "options": {"a": 0.0}}
MOVE = {"target": {"x": 1.0, "y": 2.0}, "speed": 1.5}


def document(*params: tuple[str, dict[str, Any]]) -> dict[str, Any]:
    entries = [
        {"id": f"s{n}", "skill": skill, "label": "x", "params": raw, "status": "IDLE"}
        for n, (skill, raw) in enumerate(params)
    ]
    return {"rosmc_mission": 1, "library": "unit_team", "revision": 0, "tasks": {"alpha": entries}}


def test_alike_parameters_are_checked_once_and_shared(library: Library) -> None:
    data = document(("move", MOVE), ("wait", WAIT), ("move", dict(MOVE)), ("wait", dict(WAIT)))
    content, _ = mission_from_dict(data, library)
    first_move, first_wait, move, wait = content.tasks["alpha"]
    assert move.params is first_move.params and wait.params is first_wait.params
    assert first_move.params["speed"] == 1.5 and first_wait.params["seconds"] == 3


def test_equal_values_of_another_type_or_sign_are_checked_for_themselves(
    library: Library,
) -> None:
    negative = {**WAIT, "options": {"a": -0.0}}
    whole = {**MOVE, "speed": 1}  # an int for a float parameter: converted
    data = document(("wait", WAIT), ("wait", negative), ("move", MOVE), ("move", whole))
    content, _ = mission_from_dict(data, library)
    zero, minus, _, converted = content.tasks["alpha"]
    assert math.copysign(1.0, zero.params["options"]["a"]) == 1.0
    assert math.copysign(1.0, minus.params["options"]["a"]) == -1.0
    assert type(converted.params["speed"]) is float
    # true equals 1 but is no int: refused after a skill with 1 as it is alone.
    truth = {**WAIT, "seconds": True}
    one = {**WAIT, "seconds": 1}
    with pytest.raises(MissionFileError) as alone:
        mission_from_dict(document(("wait", truth)), library)
    with pytest.raises(MissionFileError) as after:
        mission_from_dict(document(("wait", one), ("wait", truth)), library)
    assert str(after.value) == str(alone.value).replace("[0]", "[1]")
