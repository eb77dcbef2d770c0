"""Reviewing a recording offline: ``rosmc diff`` and the blueprint ``rosmc restore`` loads.

The journal is written the way the mission server writes one: a real core Mission plans,
synchronizes, executes (a success, a failure and its retry) and edits, and every accepted
event is journaled with JournalWriter at the mission's own stamp. No ROS master.
"""

from __future__ import annotations

import itertools
import json
import re
import shutil
import subprocess
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pytest

wire = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

from rosmc_server import demo  # noqa: E402
from rosmc_server.cli import main as rosmc  # noqa: E402
from rosmc_server.conversions import event_to_msg, mission_to_msg  # noqa: E402
from rosmc_server.core import (  # noqa: E402
    InvalidRequest,
    MarkerType,
    Mission,
    MissionEvent,
    Pose,
    SkillStatus,
    TaskMarker,
    Transfer,
    load_library,
)
from rosmc_server.core.files.persistence import dump_mission, parse_mission  # noqa: E402
from rosmc_server.interface import SCIENCE_TOPIC  # noqa: E402
from rosmc_server.recording import JournalWriter  # noqa: E402
from rosmc_server.recording.diff import diff_missions, resolve_when  # noqa: E402
from rosmc_server.recording.history import MissionHistory  # noqa: E402
from rosmc_server.recording.overlays import timeline_with_overlays  # noqa: E402
from rosmc_server.recording.restore import blueprint_from  # noqa: E402
from rosmc_server.recording.timeline_svg import (  # noqa: E402
    LABEL_WIDTH,
    LANE_HEIGHT,
    MARK_COLOURS,
    MARK_HEIGHT,
    OUTAGE,
    PLOT_WIDTH,
    PNG_DENSITY,
    SCORE,
    TOP,
    score_y,
)

T0 = 1_700_000_000_000_000_000
S = SkillStatus


def _states(drone_link: int) -> Any:
    return wire.AgentStates(
        agents=[
            wire.AgentState(agent="drone", link=wire.LinkState(state=drone_link)),
            wire.AgentState(agent="science_rover", link=wire.LinkState(state=1)),
        ]
    )


# (seconds, message): the drone's link is down from 50 to 110 s; the score rises to 5
# at 100 s and to 10 at 150 s. The mission's events are 10 s apart from 0 to 170 s.
TELEMETRY: list[tuple[float, Any]] = [
    (5.0, _states(1)),
    (6.0, wire.ScienceState(score=0.0)),
    (50.0, _states(2)),
    (100.0, wire.ScienceState(score=5.0)),
    (110.0, _states(1)),
    (150.0, wire.ScienceState(score=10.0)),
]


@dataclass
class Journal:
    """The journal and the revisions of interest."""

    path: Path
    planned: int  # everything planned, nothing synchronized
    retried: int  # d1 succeeded, d2 failed and was retried
    last: int
    ids: dict[str, str]


@pytest.fixture(scope="module")
def journal(tmp_path_factory: pytest.TempPathFactory) -> Journal:
    """Plan, execute and edit a mission; journal every event at its stamp (10 s apart)."""
    counter = itertools.count(1)
    clock = itertools.count(0, 10)
    mission = Mission(
        load_library(demo.LIBRARY),
        new_id=lambda prefix: f"{prefix}-{next(counter)}",
        clock=lambda: float(next(clock)),
    )
    path = tmp_path_factory.mktemp("review") / "mission.mcap"
    writer = JournalWriter.create(path, mission_to_msg(mission.state.content(), 0, 0.0), T0)
    telemetry = list(TELEMETRY)

    def do(event: MissionEvent) -> MissionEvent:
        while telemetry and telemetry[0][0] <= event.stamp:
            seconds, message = telemetry.pop(0)
            log_time = T0 + round(seconds * 1e9)
            if isinstance(message, wire.ScienceState):
                writer.append_telemetry(SCIENCE_TOPIC, message, log_time)
            else:
                writer.append_agent_states(message, log_time)
        state = mission.state
        message = event_to_msg(event, lambda skill_id: state.locate(skill_id)[0])
        writer.append_event(message, T0 + round(event.stamp * 1e9))
        return event

    def added(agent: str, skill: str, **kwargs: object) -> str:
        return do(mission.add_skill(agent, skill, **kwargs)).change.put_skills[0].skill.id  # type: ignore[arg-type]

    do(mission.add_marker(TaskMarker("RSS A", MarkerType.POSITION, Pose(10.0, 6.0))))
    ids = {
        "d1": added("drone", "take_off", params={"altitude": 12}),
        "d2": added("drone", "fly_over", params={"altitude": 9.5}),
        "d3": added("drone", "land"),
        "s4": added("science_rover", "identify_stones", bindings={"position": "RSS A"}),
        "m5": added("manipulator_rover", "identify_stones"),
        "s6": added("science_rover", "explore"),
    }
    do(mission.add_barrier([ids["s4"], ids["m5"]]))
    do(mission.add_barrier([ids["d1"], ids["s6"]]))
    planned = mission.revision
    do(mission.synchronize("drone", ids["d2"]))
    do(mission.confirm_synchronized("drone", [ids["d1"], ids["d2"]]))
    for skill_id, outcome in ((ids["d1"], S.SUCCESS), (ids["d2"], S.FAILURE)):
        do(mission.report_status(skill_id, S.RUNNING))
        do(mission.report_status(skill_id, outcome))
    ids["d2b"] = do(mission.retry(ids["d2"])).change.put_skills[1].skill.id
    retried = mission.revision
    do(mission.edit_skill(ids["s4"], {"radius": 4.0}, label="closer look"))
    do(mission.add_marker(TaskMarker("Late", MarkerType.POSITION, Pose(1.0, 2.0))))
    writer.close()
    return Journal(path, planned, retried, mission.revision, ids)


@pytest.fixture(scope="module")
def history(journal: Journal) -> MissionHistory:
    return MissionHistory.from_journal(journal.path)


def test_restore_drops_what_ran_and_resets_the_rest(
    journal: Journal, history: MissionHistory
) -> None:
    ids = journal.ids
    state = history.at_revision(journal.retried)
    # The retry went straight to the robot: synchronized, second attempt.
    assert (state.skill(ids["d2b"]).status, state.skill(ids["d2b"]).attempt) == (
        S.IDLE_SYNCHRONIZED,
        2,
    )
    restored = blueprint_from(state)
    assert restored.dropped == (ids["d1"], ids["d2"])
    assert restored.barriers_dropped == (f"{[b.id for b in state.barriers][1]}",)
    content = restored.content
    assert [s.id for s in content.tasks["drone"]] == [ids["d2b"], ids["d3"]]
    assert restored.kept == 5
    for skill in (s for task in content.tasks.values() for s in task):
        assert (skill.status, skill.transfer, skill.attempt) == (S.IDLE, Transfer.NONE, 1)
        assert skill.status_text == "" and skill.started == skill.finished == 0.0
    assert [b.skill_ids for b in content.barriers.values()] == [(ids["s4"], ids["m5"])]
    assert [m.name for m in content.markers.values()] == ["RSS A"]
    assert content.tasks["science_rover"][0].bindings == {"position": "RSS A"}
    # The document is one the server's load_mission accepts, unchanged by the round trip.
    document = dump_mission(content, state.revision)
    parsed, revision = parse_mission(document, load_library(demo.LIBRARY), "restore")
    assert (parsed, revision) == (content, state.revision)


def test_diff_shows_execution_edits_and_markers(journal: Journal, history: MissionHistory) -> None:
    ids = journal.ids
    ran = diff_missions(
        resolve_when(history, f"r{journal.planned}"), resolve_when(history, f"r{journal.retried}")
    )
    statuses = {(c.subject, c.field): (c.before, c.after) for c in ran.statuses}
    assert statuses[(ids["d1"], "status")] == ("IDLE", "SUCCESS")
    assert statuses[(ids["d2"], "status")] == ("IDLE", "FAILURE")
    assert statuses[(ids["d2"], "resolution")] == ("NONE", "RETRIED")
    assert ran.skills_added == (
        f"{ids['d2b']} (drone fly_over '{ran.after.state.skill(ids['d2b']).label}')",
    )
    assert ran.edits == () and ran.skills_removed == () and ran.markers_added == ()
    edited = diff_missions(
        resolve_when(history, f"r{journal.retried}"), resolve_when(history, f"r{journal.last}")
    )
    assert {(c.subject, c.field, c.before, c.after) for c in edited.edits} == {
        (ids["s4"], "param radius", "2", "4"),
        (ids["s4"], "label", "identify_stones", "closer look"),
    }
    assert edited.markers_added == ("Late (POSITION)",) and edited.statuses == ()
    same = diff_missions(resolve_when(history, "r3"), resolve_when(history, "r3"))
    assert same.is_empty


def test_every_way_to_name_a_moment(journal: Journal, history: MissionHistory) -> None:
    # Revision n is journaled at (n - 1) * 10 s: the clock starts at 0 and ticks 10 s.
    def revision(when: str) -> int:
        return resolve_when(history, when).state.revision

    assert revision("r5") == 5
    assert revision("40") == revision("40s") == revision("0:40") == revision("0:00:40") == 5
    assert revision("1:30") == 10
    iso = datetime.fromtimestamp((T0 + 40 * 10**9) / 1e9, UTC)
    assert revision(iso.isoformat()) == 5
    assert revision(iso.replace(tzinfo=None).isoformat()) == 5  # no zone: UTC
    with pytest.raises(InvalidRequest, match="cannot read 'soon' as a time"):
        resolve_when(history, "soon")
    with pytest.raises(InvalidRequest, match="outside the recording"):
        resolve_when(history, "2020-01-01T00:00:00")
    # Past the end in every form (what `rosmc restore --at` and `rosmc at` take): refused.
    end = history.duration
    assert resolve_when(history, f"{end:.9f}").state.revision == history.revisions[-1].revision
    for late in (f"{end + 1:g}", "9999s", "2:46:39"):
        with pytest.raises(InvalidRequest, match="outside the recording"):
            resolve_when(history, late)


def test_restore_refuses_a_time_past_the_end_before_asking_the_server(
    journal: Journal, capsys: pytest.CaptureFixture[str]
) -> None:
    # No master runs here: the refusal comes from the recording alone, as for a revision.
    assert rosmc(["restore", str(journal.path), "--at", "9999"]) == 1
    assert "'9999' is outside the recording" in capsys.readouterr().err
    assert rosmc(["restore", str(journal.path), "--at", "r9999"]) == 1
    assert "holds no revision 9999" in capsys.readouterr().err


def test_cli_diff_as_json(journal: Journal, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["--json", "diff", str(journal.path), f"r{journal.planned}", f"r{journal.last}"]
    assert rosmc(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["from"]["revision"] == journal.planned and data["to"]["revision"] == journal.last
    assert {
        "subject": journal.ids["d1"],
        "field": "status",
        "before": "IDLE",
        "after": "SUCCESS",
    } in data["statuses"]
    assert rosmc(["diff", str(journal.path), "r1", "soon"]) == 1
    assert "cannot read 'soon' as a time" in capsys.readouterr().err


# -- the timeline picture, checked by its pixels -----------------------------------------
def pixel(png: Path, x: float, y: float) -> tuple[int, int, int]:
    """The colour at SVG coordinates (x, y) of a PNG rendered at PNG_DENSITY dpi."""
    zoom = PNG_DENSITY / 96  # SVG pixels are 1/96 inch
    crop = f"1x1+{round(x * zoom)}+{round(y * zoom)}"
    text = subprocess.run(
        ["convert", str(png), "-crop", crop, "-depth", "8", "txt:-"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    found = re.search(r"#([0-9A-Fa-f]{6})", text)
    assert found is not None, text
    code = found.group(1)
    return int(code[0:2], 16), int(code[2:4], 16), int(code[4:6], 16)


def near(colour: tuple[int, int, int], hex_colour: str) -> bool:
    """Whether ``colour`` is ``hex_colour`` (#rrggbb), give or take anti-aliasing."""
    want = tuple(int(hex_colour[i : i + 2], 16) for i in (1, 3, 5))
    return all(abs(a - b) <= 12 for a, b in zip(colour, want, strict=True))


@pytest.mark.skipif(shutil.which("convert") is None, reason="ImageMagick is not installed")
def test_timeline_shows_marks_outages_and_score(
    journal: Journal, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "timeline.png"
    assert rosmc(["timeline", str(journal.path), "-o", str(png)]) == 0
    capsys.readouterr()
    history, timeline = timeline_with_overlays(journal.path)
    assert timeline.outages == (("drone", 50.0, 110.0),)
    assert timeline.score == ((6.0, 0.0), (100.0, 5.0), (150.0, 10.0))
    kinds = {mark.kind for mark in timeline.marks}
    assert kinds == {"sync", "edit"}  # nobody unsynchronized here
    scale = PLOT_WIDTH / timeline.duration
    lanes = list(timeline.lanes)

    def x(seconds: float) -> float:
        return LABEL_WIDTH + seconds * scale

    def lane_top(agent: str) -> float:
        return TOP + lanes.index(agent) * LANE_HEIGHT + 3  # above the bars

    # The drone's lane is shaded while its link was down, and only then; not the rover's.
    assert near(pixel(png, x(80), lane_top("drone")), OUTAGE)
    assert not near(pixel(png, x(30), lane_top("drone")), OUTAGE)
    assert not near(pixel(png, x(130), lane_top("drone")), OUTAGE)
    assert not near(pixel(png, x(80), lane_top("science_rover")), OUTAGE)
    # The score holds each value until the next: 5 at 120 s (half way up), 10 at 160 s.
    panel = TOP + LANE_HEIGHT * len(lanes)
    assert near(pixel(png, x(120), score_y(5.0, panel, 10.0)), SCORE)
    assert near(pixel(png, x(160), score_y(10.0, panel, 10.0)), SCORE)
    assert near(pixel(png, x(60), score_y(0.0, panel, 10.0)), SCORE)
    assert not near(pixel(png, x(120), score_y(10.0, panel, 10.0)), SCORE)
    # Operator marks in their colours above the lanes, where the changes were journaled.
    sync = next(mark for mark in timeline.marks if mark.kind == "sync")
    assert sync.time == history.seconds(history.revisions[journal.planned + 1].log_time)
    strip = TOP - MARK_HEIGHT / 2 - 2
    assert near(pixel(png, x(sync.time), strip), MARK_COLOURS["sync"])
    last_edit = history.seconds(history.revisions[-1].log_time)
    assert history.revisions[-1].revision == journal.last
    assert near(pixel(png, x(last_edit), strip), MARK_COLOURS["edit"])
    assert not near(pixel(png, x(sync.time + 5), strip), MARK_COLOURS["sync"])


# -- rosmc info ----------------------------------------------------------------------------
def test_info_counts_outcomes_attempts_outages_and_score(
    journal: Journal, capsys: pytest.CaptureFixture[str]
) -> None:
    assert rosmc(["--json", "info", str(journal.path)]) == 0
    data = json.loads(capsys.readouterr().out)
    drone = next(robot for robot in data["robots"] if robot["agent"] == "drone")
    # d1 succeeded, d2 failed and was retried, the retry waits on the robot, d3 unsent.
    assert (drone["succeeded"], drone["retried"], drone["unfinished"]) == (1, 1, 1)
    assert (drone["blueprint"], drone["attempts"]) == (1, 2)
    assert data["outages"] == [{"agent": "drone", "start_s": 50.0, "end_s": 110.0}]
    assert data["final_score"] == 10.0
    assert rosmc(["info", str(journal.path)]) == 0
    text = capsys.readouterr().out
    assert (
        "  drone                1 succeeded, 1 retried, 1 unfinished, 1 blueprint (2 attempts)\n"
        in text
    )
    assert "  drone                50.0 s to 110.0 s (60.0 s)\n" in text
    assert "score 10.00 at the end (3 records)\n" in text


def test_info_says_what_a_recording_lacks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mission = Mission(load_library(demo.LIBRARY))
    path = tmp_path / "bare.mcap"
    JournalWriter.create(path, mission_to_msg(mission.state.content(), 0, 0.0), T0).close()
    assert rosmc(["info", str(path)]) == 0
    text = capsys.readouterr().out
    assert "link outages: no agent states recorded\n" in text
    assert "score: not recorded (no simulator science state)\n" in text
