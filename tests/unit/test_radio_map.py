"""The radio map (core/robots/radio_map.py): readings, prediction, the task-end warning."""

from __future__ import annotations

import math

from rosmc_server.core import LostLinkKind, LostLinkPolicy, Pose, SkillInstance, SkillStatus
from rosmc_server.core.robots.radio_map import (
    GridSpec,
    Prediction,
    RadioMap,
    Reading,
    coverage_warning,
    plan_end,
    reading_text,
)

RETURN = LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, skill="navigate_to")
S = SkillStatus


def skill(skill_id: str, status: SkillStatus, **params: object) -> SkillInstance:
    return SkillInstance(skill_id, "rover", "navigate_to", skill_id, dict(params), status=status)


def model() -> Prediction:
    """A 30 x 1 strip along x from 0: covered up to 12 m."""
    grid = GridSpec(0.0, 0.0, 1.0, 30, 1)
    signal = [-40.0 - 25.0 * math.log10(max(1.0, x)) for x in range(30)]
    return Prediction(grid, signal, [x <= 12 for x in range(30)])


def test_the_newest_reading_of_a_cell_stays_and_the_last_link_follows_coverage() -> None:
    radio = RadioMap()
    radio.add(Reading("a", 5.1, 0.0, -60.0, True, 10.0))
    radio.add(Reading("a", 5.2, 0.1, -61.0, True, 12.0))
    radio.add(Reading("a", 5.0, 0.0, -59.0, True, 11.0))  # late: older than the kept one
    radio.add(Reading("a", 15.0, 0.0, -90.0, False, 20.0))
    radio.add(Reading("b", math.nan, 0.0, -50.0, True, 21.0))  # no position: ignored
    assert sorted(r.dbm for r in radio.readings()) == [-90.0, -61.0]
    assert radio.last_link["a"].stamp == 12.0 and "b" not in radio.last_link


def test_an_estimate_prefers_a_reading_nearby_to_the_model() -> None:
    radio = RadioMap(prediction=model())
    assert radio.estimate(11.0, 0.0).covered  # type: ignore[union-attr]
    far = radio.estimate(17.0, 0.0)
    assert far is not None and not far.covered and not far.measured
    radio.add(Reading("a", 11.4, 0.0, -95.0, False, 5.0))  # a rock the model does not know
    near = radio.estimate(11.0, 0.0)
    assert near is not None and near.measured and not near.covered
    assert radio.estimate(40.0, 40.0) is None  # neither measured nor modelled


def test_an_old_reading_says_how_old_it_is() -> None:
    reading = Reading("a", 0.0, 0.0, -72.4, True, 100.0)
    assert reading_text(reading, 126.2) == "-72 dBm 26 s ago"
    assert reading_text(reading, 100.5) == "-72 dBm now"


def test_the_plan_ends_at_the_last_pose_still_to_run() -> None:
    task = [
        skill("done", S.SUCCESS, target=Pose(1.0, 0.0)),
        skill("out", S.IDLE_SYNCHRONIZED, target=Pose(17.0, 0.0), speed=0.5),
        skill("wait", S.IDLE_SYNCHRONIZED, seconds=3.0),
        skill("plan", S.IDLE, target=Pose(2.0, 0.0)),  # blueprint: not on the robot yet
    ]
    assert plan_end(task) == Pose(17.0, 0.0)
    assert plan_end(task[:1]) is None


def test_a_plan_ending_out_of_coverage_warns_only_under_a_policy_that_leaves_it_there() -> None:
    radio = RadioMap(prediction=model())
    out = [skill("out", S.RUNNING, target=Pose(17.0, 0.0))]
    warning = coverage_warning(out, radio, LostLinkPolicy(), RETURN)
    assert warning.startswith("the task ends out of coverage at (17.0, 0.0) (predicted ")
    assert coverage_warning(out, radio, LostLinkPolicy(LostLinkKind.HOLD), None)
    assert coverage_warning(out, radio, RETURN, None) == ""
    # Before the robot reports a policy, the library default counts.
    assert coverage_warning(out, radio, None, RETURN) == ""
    assert coverage_warning(out, radio, None, None)
    inside = [skill("in", S.RUNNING, target=Pose(8.0, 0.0))]
    assert coverage_warning(inside, radio, LostLinkPolicy(), None) == ""
