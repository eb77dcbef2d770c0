"""Synchronization with the robot: upload a prefix, confirm or decline, unsynchronize."""

from __future__ import annotations

from typing import Any

import pytest

from rosmc_server.core import (
    EventKind,
    InvalidRequest,
    NotFound,
    RuleViolation,
    SkillStatus,
    Transfer,
)

S = SkillStatus


def transfers(mission: Any, agent: str) -> list[tuple[str, str]]:
    return [(s.status.name, s.transfer.name) for s in mission.state.task(agent)]


# -- synchronize -----------------------------------------------------------------


def test_synchronize_a_prefix(mission: Any, drv: Any, accepted: Any) -> None:
    a1, a2, a3 = drv.adds("alpha", 3)
    event = accepted(mission, EventKind.SYNC_REQUESTED, mission.synchronize, "alpha", a2)
    assert event.agent == "alpha" and a1 in event.summary and a2 in event.summary
    assert [p.skill.id for p in event.change.put_skills] == [a1, a2]
    assert transfers(mission, "alpha") == [
        ("IDLE", "UPLOADING"),
        ("IDLE", "UPLOADING"),
        ("IDLE", "NONE"),
    ]
    sections = mission.state.sections("alpha")
    assert (sections.synced_end, sections.editable_start) == (0, 2)
    event = accepted(
        mission, EventKind.SYNC_CONFIRMED, mission.confirm_synchronized, "alpha", [a1, a2]
    )
    assert [(s.status, s.transfer) for s in (mission.state.skill(i) for i in (a1, a2))] == [
        (S.IDLE_SYNCHRONIZED, Transfer.NONE)
    ] * 2
    assert mission.state.skill(a3).status is S.IDLE


def test_synchronize_whole_blueprint(mission: Any, drv: Any) -> None:
    ids = drv.adds("alpha", 3)
    assert drv.sync("alpha") == ids
    assert all(drv.status(i) is S.IDLE_SYNCHRONIZED for i in ids)
    drv.add("bravo")
    event = mission.synchronize("bravo", "")  # "" means the whole blueprint too
    assert len(event.change.put_skills) == 1


def test_synchronize_after_an_upload_appends_to_it(mission: Any, drv: Any) -> None:
    a1, a2 = drv.adds("alpha", 2)
    mission.synchronize("alpha", a1)
    mission.synchronize("alpha", a2)
    mission.confirm_synchronized("alpha", [a1])
    mission.confirm_synchronized("alpha", [a2])
    assert [drv.status(a1), drv.status(a2)] == [S.IDLE_SYNCHRONIZED] * 2


def test_synchronize_refusals(mission: Any, drv: Any, rejected: Any) -> None:
    rejected(mission, RuleViolation, mission.synchronize, "alpha", match="no blueprint skills")
    rejected(mission, NotFound, mission.synchronize, "zulu", match="zulu")
    synced, uploading, blueprint = drv.adds("alpha", 3)
    other = drv.add("bravo")
    drv.sync("alpha", synced)
    mission.synchronize("alpha", uploading)
    rejected(mission, NotFound, mission.synchronize, "alpha", "ghost", match="'ghost'")
    for not_editable in (synced, uploading, other):
        rejected(
            mission, RuleViolation, mission.synchronize, "alpha", not_editable,
            match="not in alpha's editable blueprint",
        )  # fmt: skip
    mission.delete_skills([blueprint])
    rejected(mission, RuleViolation, mission.synchronize, "alpha", match="no blueprint skills")


def test_synchronize_refused_while_unsync_pending(mission: Any, drv: Any, rejected: Any) -> None:
    a1, a2 = drv.adds("alpha", 2)
    drv.sync("alpha", a1)
    mission.unsynchronize("alpha")
    rejected(mission, RuleViolation, mission.synchronize, "alpha", match="unsynchronize")
    rejected(mission, RuleViolation, mission.synchronize, "alpha", a2, match="unsynchronize")


def test_synchronize_on_stale_revision(mission: Any, drv: Any, rejected: Any) -> None:
    from rosmc_server.core import StaleRevision

    drv.add("alpha")
    rejected(mission, StaleRevision, mission.synchronize, "alpha", base_revision=0)
    mission.synchronize("alpha", base_revision=1)


# -- confirm and decline ---------------------------------------------------------


@pytest.fixture
def uploading(mission: Any, drv: Any) -> list[str]:
    ids = drv.adds("alpha", 3)
    mission.synchronize("alpha")
    return ids


def test_confirm_in_parts(mission: Any, drv: Any, uploading: list[str]) -> None:
    u1, u2, u3 = uploading
    mission.confirm_synchronized("alpha", [u1])
    assert transfers(mission, "alpha") == [
        ("IDLE_SYNCHRONIZED", "NONE"),
        ("IDLE", "UPLOADING"),
        ("IDLE", "UPLOADING"),
    ]
    mission.confirm_synchronized("alpha", [u2, u3])
    assert all(drv.status(i) is S.IDLE_SYNCHRONIZED for i in uploading)


@pytest.mark.parametrize(
    ("answer", "error", "fragment"),
    [
        ([], InvalidRequest, "names no skills"),
        (["u2"], RuleViolation, "not the first"),
        (["u2", "u1"], RuleViolation, "not the first"),
        (["u1", "u3"], RuleViolation, "not the first"),
        (["u1", "u2", "u3", "u3"], RuleViolation, "not the first"),
        (["ghost"], RuleViolation, "not the first"),
        (["b1"], RuleViolation, "not the first"),
    ],
)
def test_confirm_must_name_the_first_uploads_in_order(
    mission: Any, drv: Any, rejected: Any, uploading: list[str], answer: list[str], error: Any,
    fragment: str,
) -> None:  # fmt: skip
    names = dict(zip(("u1", "u2", "u3"), uploading, strict=True))
    names["b1"] = drv.add("alpha")
    answer = [names.get(a, a) for a in answer]
    rejected(mission, error, mission.confirm_synchronized, "alpha", answer, match=fragment)


def test_confirm_without_pending_upload(mission: Any, drv: Any, rejected: Any) -> None:
    skill = drv.add("alpha")
    rejected(mission, RuleViolation, mission.confirm_synchronized, "alpha", [skill])
    rejected(mission, NotFound, mission.confirm_synchronized, "zulu", [skill])


def test_decline_returns_the_last_uploads(
    mission: Any, drv: Any, accepted: Any, uploading: list[str]
) -> None:
    u1, u2, u3 = uploading
    event = accepted(
        mission, EventKind.SYNC_DECLINED, mission.decline_synchronize, "alpha", [u2, u3],
        "  robot busy ",
    )  # fmt: skip
    assert "robot busy" in event.summary
    assert transfers(mission, "alpha") == [
        ("IDLE", "UPLOADING"),
        ("IDLE", "NONE"),
        ("IDLE", "NONE"),
    ]
    assert mission.state.skill(u2).status_text == "robot busy"
    # Declined skills are editable again; the still-uploading one is not.
    mission.edit_skill(u2, label="again")
    mission.decline_synchronize("alpha", [u1], "")
    assert mission.state.skill(u1).status_text == "declined by the robot"
    assert mission.state.sections("alpha").editable_start == 0


@pytest.mark.parametrize(
    "answer",
    [["u1"], ["u3", "u2"], ["u1", "u3"], [], ["ghost"]],
)
def test_decline_must_name_the_last_uploads_in_order(
    mission: Any, rejected: Any, uploading: list[str], answer: list[str]
) -> None:
    names = dict(zip(("u1", "u2", "u3"), uploading, strict=True))
    answer = [names.get(a, a) for a in answer]
    error = InvalidRequest if not answer else RuleViolation
    rejected(mission, error, mission.decline_synchronize, "alpha", answer, "no")


def test_confirm_and_decline_ignore_base_revision(mission: Any, uploading: list[str]) -> None:
    # Robot answers are not operator requests: they never carry a base revision.
    mission.decline_synchronize("alpha", uploading[2:], "x")
    mission.confirm_synchronized("alpha", uploading[:2])


# -- unsynchronize ---------------------------------------------------------------


def test_unsync_default_is_the_not_started_suffix(mission: Any, drv: Any, accepted: Any) -> None:
    done, s2, s3 = drv.adds("alpha", 3)
    blueprint = drv.add("alpha")
    drv.sync("alpha", s3)
    drv.finish(done)
    event = accepted(mission, EventKind.UNSYNC_REQUESTED, mission.unsynchronize, "alpha")
    assert [p.skill.id for p in event.change.put_skills] == [s2, s3]
    assert transfers(mission, "alpha") == [
        ("SUCCESS", "NONE"),
        ("IDLE_SYNCHRONIZED", "REMOVING"),
        ("IDLE_SYNCHRONIZED", "REMOVING"),
        ("IDLE", "NONE"),
    ]
    # Until the robot confirms, nothing changes section and nothing is editable.
    assert mission.state.sections("alpha").synced_end == 3
    event = accepted(
        mission, EventKind.UNSYNC_CONFIRMED, mission.confirm_unsynchronized, "alpha", [s2, s3]
    )
    assert drv.ids("alpha") == [done, s2, s3, blueprint]
    assert transfers(mission, "alpha") == [
        ("SUCCESS", "NONE"),
        ("IDLE", "NONE"),
        ("IDLE", "NONE"),
        ("IDLE", "NONE"),
    ]
    # They are at the front of the blueprint, editable again.
    assert mission.state.sections("alpha").editable_start == 1
    mission.edit_skill(s2, label="edited")


def test_unsync_from_a_chosen_skill(mission: Any, drv: Any) -> None:
    s1, s2, s3 = drv.adds("alpha", 3)
    drv.sync("alpha")
    event = mission.unsynchronize("alpha", s2)
    assert [p.skill.id for p in event.change.put_skills] == [s2, s3]
    mission.confirm_unsynchronized("alpha", [s2, s3])
    assert [drv.status(i) for i in (s1, s2, s3)] == [S.IDLE_SYNCHRONIZED, S.IDLE, S.IDLE]


def test_unsync_while_pending_is_not_editable(mission: Any, drv: Any, rejected: Any) -> None:
    _, s2 = drv.adds("alpha", 2)
    drv.sync("alpha")
    mission.unsynchronize("alpha", s2)
    rejected(mission, RuleViolation, mission.edit_skill, s2, label="x")
    rejected(mission, RuleViolation, mission.delete_skills, [s2])
    rejected(mission, InvalidRequest, mission.reorder, "alpha", [s2])
    rejected(mission, RuleViolation, mission.add_barrier, [s2, drv.add("bravo")])
    rejected(mission, InvalidRequest, mission.add_skill, "alpha", "move", index=1)


def test_unsync_refusals(mission: Any, drv: Any, rejected: Any) -> None:
    rejected(mission, RuleViolation, mission.unsynchronize, "alpha", match="not started")
    rejected(mission, NotFound, mission.unsynchronize, "zulu")
    done, running, s3, s4 = drv.adds("alpha", 4)
    blueprint = drv.add("alpha")
    other = drv.add("bravo")
    drv.sync("alpha", s4)
    drv.finish(done)
    drv.run(running)
    rejected(mission, NotFound, mission.unsynchronize, "alpha", "ghost")
    for started in (done, running):
        rejected(mission, RuleViolation, mission.unsynchronize, "alpha", started, match="started")
    for outside in (blueprint, other):
        rejected(
            mission, RuleViolation, mission.unsynchronize, "alpha", outside,
            match="not in alpha's synchronized section",
        )  # fmt: skip
    mission.unsynchronize("alpha", s4)
    rejected(mission, RuleViolation, mission.unsynchronize, "alpha", match="already awaits")
    rejected(mission, RuleViolation, mission.unsynchronize, "alpha", s3, match="already awaits")


def test_take_back_during_an_upload_cancels_it(mission: Any, drv: Any, rejected: Any) -> None:
    """One rule for the server and the GUIs: what the robot has not confirmed can always
    be taken back (the upload is cancelled); what it has, once it has answered."""
    s1, s2, s3 = drv.adds("alpha", 3)
    drv.sync("alpha", s1)
    mission.synchronize("alpha")
    rejected(mission, RuleViolation, mission.unsynchronize, "alpha", s1, match="upload")
    event = mission.unsynchronize("alpha", s3)
    assert event.kind is EventKind.UPLOAD_CANCELLED
    assert [p.skill.id for p in event.change.put_skills] == [s3]
    event = mission.unsynchronize("alpha")
    assert event.kind is EventKind.UPLOAD_CANCELLED
    assert [p.skill.id for p in event.change.put_skills] == [s2]
    assert not mission.state.pending("alpha", Transfer.UPLOADING)


def test_unsync_refused_when_everything_started(mission: Any, drv: Any, rejected: Any) -> None:
    s1, s2 = drv.adds("alpha", 2)
    drv.sync("alpha")
    drv.finish(s1)
    drv.finish(s2, S.FAILURE)
    rejected(mission, RuleViolation, mission.unsynchronize, "alpha", match="not started")


def test_unsync_confirm_with_a_started_skill_kept(mission: Any, drv: Any, accepted: Any) -> None:
    s1, s2, s3 = drv.adds("alpha", 3)
    drv.sync("alpha")
    mission.unsynchronize("alpha")
    # The robot had already started s1 when the request arrived: it gives back s2, s3.
    event = accepted(
        mission, EventKind.UNSYNC_CONFIRMED, mission.confirm_unsynchronized, "alpha", [s2, s3]
    )
    assert f"kept {s1}" in event.summary and "started" in event.summary
    assert transfers(mission, "alpha") == [
        ("IDLE_SYNCHRONIZED", "NONE"),
        ("IDLE", "NONE"),
        ("IDLE", "NONE"),
    ]
    drv.run(s1)


def test_unsync_confirm_of_nothing_keeps_all(mission: Any, drv: Any) -> None:
    drv.adds("alpha", 2)
    drv.sync("alpha")
    mission.unsynchronize("alpha")
    event = mission.confirm_unsynchronized("alpha", [])
    assert "gave back nothing" in event.summary
    assert transfers(mission, "alpha") == [("IDLE_SYNCHRONIZED", "NONE")] * 2


def test_a_report_during_unsync_keeps_the_skill_synchronized(mission: Any, drv: Any) -> None:
    s1, s2 = drv.adds("alpha", 2)
    drv.sync("alpha")
    mission.unsynchronize("alpha")
    drv.run(s1)  # the robot started s1 before the request reached it
    assert mission.state.skill(s1).transfer is Transfer.NONE
    mission.confirm_unsynchronized("alpha", [s2])
    assert transfers(mission, "alpha") == [("RUNNING", "NONE"), ("IDLE", "NONE")]


@pytest.mark.parametrize(
    "answer",
    [["s1"], ["s1", "s2", "s3", "s4"], ["s3", "s2"], ["s2"], ["ghost"], ["b1"]],
)
def test_unsync_confirm_must_name_the_last_removals(
    mission: Any, drv: Any, rejected: Any, answer: list[str]
) -> None:
    ids = drv.adds("alpha", 3)
    drv.sync("alpha")
    mission.unsynchronize("alpha")
    names = dict(zip(("s1", "s2", "s3"), ids, strict=True))
    names["b1"] = drv.add("alpha")
    answer = [names.get(a, a) for a in answer]
    rejected(mission, RuleViolation, mission.confirm_unsynchronized, "alpha", answer)


def test_unsync_confirm_without_request(mission: Any, drv: Any, rejected: Any) -> None:
    drv.adds("alpha", 2)
    drv.sync("alpha")
    rejected(mission, RuleViolation, mission.confirm_unsynchronized, "alpha", [], match="no unsync")
    rejected(mission, NotFound, mission.confirm_unsynchronized, "zulu", [])


def test_unsync_after_retry_takes_the_new_instance(mission: Any, drv: Any) -> None:
    failed, later = drv.adds("alpha", 2)
    drv.sync("alpha")
    drv.finish(failed, S.FAILURE)
    fresh = mission.retry(failed).change.put_skills[1].skill.id
    event = mission.unsynchronize("alpha")
    assert [p.skill.id for p in event.change.put_skills] == [fresh, later]
    mission.confirm_unsynchronized("alpha", [fresh, later])
    assert drv.ids("alpha") == [failed, fresh, later]
    assert mission.state.skill(fresh).attempt == 2
    assert mission.state.sections("alpha").synced_end == 1


# -- cancelling an unanswered upload ---------------------------------------------------


def test_cancel_uploads(mission: Any, drv: Any, accepted: Any, uploading: list[str]) -> None:
    event = accepted(mission, EventKind.UPLOAD_CANCELLED, mission.cancel_uploads, "alpha")
    assert event.agent == "alpha" and all(i in event.summary for i in uploading)
    assert transfers(mission, "alpha") == [("IDLE", "NONE")] * 3
    assert mission.state.sections("alpha").editable_start == 0
    # Once cancelled, a late answer from the robot is refused.
    with pytest.raises(RuleViolation):
        mission.confirm_synchronized("alpha", uploading[:1])


def test_cancel_uploads_refusals(mission: Any, drv: Any, rejected: Any) -> None:
    from rosmc_server.core import StaleRevision

    rejected(mission, RuleViolation, mission.cancel_uploads, "alpha", match="no upload")
    rejected(mission, NotFound, mission.cancel_uploads, "zulu")
    drv.adds("alpha", 2)
    drv.sync("alpha")
    rejected(mission, RuleViolation, mission.cancel_uploads, "alpha", match="no upload")
    drv.add("alpha")
    mission.synchronize("alpha")
    rejected(mission, StaleRevision, mission.cancel_uploads, "alpha", base_revision=0)
    mission.cancel_uploads("alpha", base_revision=mission.revision)
