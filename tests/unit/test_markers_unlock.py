"""A task marker is locked only while an unfinished synchronized skill uses it.

Once every synchronized skill bound to it has finished (success or failure), the marker
can move and be renamed again; the finished skills keep the values they ran with.
"""

from __future__ import annotations

from typing import Any

from rosmc_server.core import MarkerType, Pose, RuleViolation, SkillStatus, TaskMarker


def test_finished_skills_release_their_marker(mission: Any, drv: Any, rejected: Any) -> None:
    mission.add_marker(TaskMarker("goal", MarkerType.POSE, Pose(1.0, 1.0)))
    used = drv.add("alpha", "move", bindings={"target": "goal"})
    drv.sync("alpha")
    rejected(mission, RuleViolation, mission.move_marker, "goal", Pose(2.0, 2.0), ())
    drv.finish(used)
    assert mission.state.skill(used).status is SkillStatus.SUCCESS
    ran_with = mission.state.skill(used).params["target"]
    mission.move_marker("goal", Pose(5.0, 5.0), ())
    assert mission.state.marker("goal").pose == Pose(5.0, 5.0)
    assert mission.state.skill(used).params["target"] == ran_with, "the log is kept"
    # a new blueprint skill bound to it follows the marker again
    later = drv.add("alpha", "move", bindings={"target": "goal"})
    mission.move_marker("goal", Pose(6.0, 6.0), ())
    assert mission.state.skill(later).params["target"] == Pose(6.0, 6.0)
    mission.rename_marker("goal", "new goal")
    assert mission.state.skill(later).bindings["target"] == "new goal"
