"""Recordings reviewed offline: the mission at any revision or time, timelines, pictures, bags.

The recording is made the way the mission server makes one: the scripted demo mission
(rosmc_server.demo) and a second act with pauses, a failure and retry, a barrier whose
robots report late, a stop and a mission replacement, every event journaled with
JournalWriter right after the core accepted it. No ROS master.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

wire = pytest.importorskip("rosmc.msg", reason="rosmc messages are not built (source build/devel)")

import genpy  # noqa: E402
import rosbag  # noqa: E402

from rosmc_server import demo  # noqa: E402
from rosmc_server.cli import main as rosmc  # noqa: E402
from rosmc_server.conversions import event_to_msg, mission_to_msg  # noqa: E402
from rosmc_server.core import (  # noqa: E402
    EventKind,
    InvalidRequest,
    Mission,
    MissionContent,
    MissionEvent,
    NotFound,
    SkillStatus,
    Transfer,
    load_library,
)
from rosmc_server.interface import EVENTS_TOPIC, MISSION_TOPIC, ROBOT_REPORTS_TOPIC  # noqa: E402
from rosmc_server.recording import JournalWriter, read_journal  # noqa: E402
from rosmc_server.recording.bag_clock import MissionClock  # noqa: E402
from rosmc_server.recording.history import MissionHistory  # noqa: E402
from rosmc_server.recording.timeline_svg import (  # noqa: E402
    OLIVE,
    RED,
    TimelineExportError,
    render_svg,
    write_timeline,
)
from rosmc_server.recording.to_rosbag import journal_to_rosbag  # noqa: E402

T0 = 1_700_000_000_000_000_000
REPO = Path(__file__).resolve().parents[2]
SVG = "{http://www.w3.org/2000/svg}"
S = SkillStatus


@dataclass
class Recording:
    """A journal and what the live mission was at every revision."""

    path: Path
    live: dict[int, MissionContent] = field(default_factory=dict)
    log_times: dict[int, int] = field(default_factory=dict)
    robot: dict[str, float] = field(default_factory=dict)  # robot stamps the test chose


class Recorder(list[MissionEvent]):
    """The event list handed to demo.run: journals each event as the server does."""

    def __init__(self, path: Path) -> None:
        super().__init__()
        self.recording = Recording(path)
        self.mission: Mission | None = None
        self.writer: JournalWriter | None = None
        self.reports: list[Any] = []  # robot reports to journal before the next event

    def attach(self, mission: Mission) -> None:
        self.mission = mission
        snapshot = mission_to_msg(mission.state.content(), mission.revision, 0.0)
        self.writer = JournalWriter.create(self.recording.path, snapshot, T0)
        self.recording.live[mission.revision] = mission.state.content()
        self.recording.log_times[mission.revision] = T0

    def append(self, event: MissionEvent) -> None:
        super().append(event)
        assert self.mission is not None and self.writer is not None
        state = self.mission.state
        log_time = T0 + round(event.stamp * 1e9)
        for report in self.reports:
            self.writer.append_report(report, log_time)
        self.reports.clear()
        self.writer.append_event(event_to_msg(event, lambda s: state.locate(s)[0]), log_time)
        if event.kind is EventKind.MISSION_REPLACED:
            snapshot = mission_to_msg(state.content(), event.revision, event.stamp)
            self.writer.append_snapshot(snapshot, log_time)
        self.recording.live[event.revision] = state.content()
        self.recording.log_times[event.revision] = log_time

    @property
    def last_stamp(self) -> float:
        return self[-1].stamp


def second_act(rec: Recorder) -> None:
    """Pause, fail and retry; a barrier with a late report; stop; unsync; a new mission."""
    mission = rec.mission
    assert mission is not None and rec.writer is not None

    def status(skill_id: str, status: S, robot: float | None = None, text: str = "") -> None:
        if robot is not None:
            agent = mission.state.locate(skill_id)[0]
            rec.reports.append(
                wire.RobotReport(
                    agent=agent,
                    seq=len(rec),
                    stamp=genpy.Time.from_sec(robot),
                    skill_id=skill_id,
                    status=wire.SkillStatus(int(status)),
                    attempt=mission.state.skill(skill_id).attempt,
                    status_text=text,
                )
            )
        rec.append(mission.report_status(skill_id, status, text=text, stamp=robot))

    for step in (S.RUNNING, S.PAUSED, S.RUNNING):
        status("drone-2", step)
    status("drone-2", S.FAILURE, text="lost GPS")
    rec.append(mission.retry("drone-2"))
    retried = rec[-1].change.put_skills[1].skill.id
    status(retried, S.RUNNING)
    status(retried, S.SUCCESS)
    for skill_id in ("manipulator_rover-7", "manipulator_rover-8"):
        status(skill_id, S.RUNNING)
        status(skill_id, S.SUCCESS)
    # A periodic snapshot, then one of an older revision written late (the server builds
    # them off the service path): neither may change the history.
    rec.writer.append_snapshot(
        mission_to_msg(mission.state.content(), mission.revision, rec.last_stamp),
        rec.recording.log_times[mission.revision] + 1,
    )
    stale = rec.recording.live[mission.revision - 3]
    late = rec.recording.log_times[mission.revision] + 2
    rec.writer.append_snapshot(mission_to_msg(stale, mission.revision - 3, 0.0), late)
    # The science rover reached the barrier long before the ground heard of it.
    rec.recording.robot["waits"] = rec.last_stamp + 1
    status("science_rover-5", S.SYNCWAITING, robot=rec.recording.robot["waits"])
    status("manipulator_rover-9", S.SYNCWAITING)
    rec.recording.robot["released"] = release = rec.last_stamp + 2
    status("science_rover-5", S.RUNNING, robot=release)
    status("manipulator_rover-9", S.RUNNING, robot=release)
    status("science_rover-5", S.SUCCESS)
    status("manipulator_rover-9", S.SUCCESS)
    status("manipulator_rover-10", S.RUNNING)
    rec.append(mission.stop("manipulator_rover"))
    for agent in ("manipulator_rover", "drone"):
        rec.append(mission.unsynchronize(agent))
        removing = [s.id for s in mission.state.task(agent) if s.transfer is Transfer.REMOVING]
        rec.append(mission.confirm_unsynchronized(agent, removing))
    rec.append(mission.new_mission())
    rec.append(mission.add_skill("drone", "take_off", {"altitude": 5.0}))


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Recording:
    """The demo mission and the second act, journaled; the journal is closed."""
    rec = Recorder(tmp_path_factory.mktemp("history") / "mission.mcap")

    class Recorded(Mission):
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            rec.attach(self)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(demo, "Mission", Recorded)
        patch.setattr(demo, "print_tasks", lambda *_: None)
        demo.run(rec)
    second_act(rec)
    assert rec.writer is not None
    rec.writer.close()
    return rec.recording


@pytest.fixture(scope="module")
def history(recording: Recording) -> MissionHistory:
    return MissionHistory.from_journal(recording.path)


def seconds(recording: Recording, revision: int) -> float:
    return (recording.log_times[revision] - T0) / 1e9


# -- the mission at every revision and time ----------------------------------------------


def test_every_revision_is_the_live_mission(recording: Recording, history: MissionHistory) -> None:
    assert [r.revision for r in history.revisions] == sorted(recording.live)
    assert history.problems == ()
    for revision, content in recording.live.items():
        state = history.at_revision(revision)
        assert state.revision == revision
        assert state.content() == content, f"revision {revision}"


def test_the_replacement_restarts_from_its_snapshot(
    recording: Recording, history: MissionHistory
) -> None:
    replaced = next(r for r in history.revisions if r.kind is EventKind.MISSION_REPLACED)
    state = history.at_revision(replaced.revision)
    assert all(not task for task in state.content().tasks.values())
    assert [m.name for m in state.markers] == ["Area 1", "RSS A", "Wi-Fi spot"]
    last = history.at_revision(replaced.revision + 1)
    assert [s.skill for s in last.task("drone")] == ["take_off"]


def test_at_time_is_the_revision_current_then(
    recording: Recording, history: MissionHistory
) -> None:
    times = recording.log_times
    for revision in recording.live:
        # The last revision journaled by then (the first event shares the snapshot's time).
        current = max(r for r in recording.live if times[r] <= times[revision])
        at = seconds(recording, revision)
        assert history.at_time(at).revision == current
        assert history.at_time(times[revision], log_time=True).revision == current
        assert history.at_time(at + 0.001).content() == recording.live[current]
    assert history.at_time(0.0).revision == 1
    assert history.at_time(1e6).revision == max(recording.live)
    assert history.revision_at(seconds(recording, 7) + 1).revision == 7
    with pytest.raises(InvalidRequest):
        history.at_time(-1.0)
    with pytest.raises(NotFound, match="holds no revision 999"):
        history.at_revision(999)


def test_a_missing_revision_is_reported_and_the_next_snapshot_resumes(
    recording: Recording, tmp_path: Path
) -> None:
    records = read_journal(recording.path).records
    path = tmp_path / "gap.mcap"
    with JournalWriter.create(path, records[0].message, records[0].log_time) as writer:
        for record in records[1:]:
            if record.topic == EVENTS_TOPIC and record.message.revision == 20:
                continue
            if record.topic == EVENTS_TOPIC:
                writer.append_event(record.message, record.log_time)
            elif record.topic == MISSION_TOPIC:
                writer.append_snapshot(record.message, record.log_time)
    gap = MissionHistory.from_journal(path)
    [lost] = gap.gaps
    replaced = lost.revisions.last + 1  # the snapshot of the mission replacement
    assert lost.revisions.first == 20 and lost.resumed_at == replaced
    assert gap.problems == (
        f"journal {path}: {replaced - 20} revisions r20..r{replaced - 1} cannot be rebuilt; "
        f"the mission continues from the snapshot of r{replaced}",
    )
    assert gap.at_revision(19).content() == recording.live[19]
    with pytest.raises(NotFound):
        gap.at_revision(20)
    newest = max(recording.live)
    assert gap.at_revision(newest).content() == recording.live[newest]  # after the replacement


# -- the timeline ------------------------------------------------------------------------


def lane(history: MissionHistory, agent: str) -> list[tuple[str, S, S | None, int]]:
    return [(i.label, i.status, i.outcome, i.attempt) for i in history.timeline().lanes[agent]]


def test_one_lane_per_robot_with_every_execution(history: MissionHistory) -> None:
    timeline = history.timeline()
    assert list(timeline.lanes) == ["drone", "science_rover", "manipulator_rover"]
    assert lane(history, "drone") == [
        ("take_off", S.RUNNING, S.SUCCESS, 1),
        ("fly_over", S.RUNNING, S.PAUSED, 1),
        ("fly_over", S.PAUSED, S.RUNNING, 1),
        ("fly_over", S.RUNNING, S.FAILURE, 1),
        ("fly_over", S.RUNNING, S.SUCCESS, 2),
    ]
    manipulator = lane(history, "manipulator_rover")
    assert manipulator[0] == ("pick_box", S.RUNNING, S.SUCCESS, 1)
    assert manipulator[1] == ("place_box", S.RUNNING, S.IDLE_SYNCHRONIZED, 1)  # stopped
    assert manipulator[-1] == ("pick_stone", S.RUNNING, S.IDLE_SYNCHRONIZED, 1)
    for interval in timeline.intervals:
        assert 0 <= interval.start <= interval.end <= timeline.duration
    assert timeline.duration == pytest.approx(history.duration)


def test_intervals_use_the_robots_stamps(recording: Recording, history: MissionHistory) -> None:
    take_off = history.timeline().lanes["drone"][0]
    skill = next(
        s
        for content in reversed(recording.live.values())
        for s in content.tasks["drone"]
        if s.id == take_off.skill_id
    )
    assert (take_off.start, take_off.end) == pytest.approx((skill.started, skill.finished))


def test_barrier_waits_and_release_on_the_robots_clock(
    recording: Recording, history: MissionHistory
) -> None:
    timeline = history.timeline()
    waits = {i.agent: i for i in timeline.intervals if i.status is S.SYNCWAITING and i.barrier}
    released = recording.robot["released"]
    science = waits["science_rover"]
    assert science.start == pytest.approx(recording.robot["waits"])  # not when the ground heard
    assert science.end == pytest.approx(released)
    assert waits["manipulator_rover"].end == pytest.approx(released)
    (release,) = timeline.releases
    assert release.time == pytest.approx(released)
    assert release.barrier == science.barrier
    assert sorted(release.members) == [
        ("manipulator_rover", "manipulator_rover-9"),
        ("science_rover", "science_rover-5"),
    ]


# -- pictures ----------------------------------------------------------------------------


def test_svg_is_well_formed_with_one_lane_per_robot(history: MissionHistory) -> None:
    timeline = history.timeline()
    root = ET.fromstring(render_svg(timeline, "mission <demo> & more"))
    lanes = root.findall(f"{SVG}g[@class='lane']")
    assert [g.get("data-agent") for g in lanes] == list(timeline.lanes)
    assert len(root.findall(f".//{SVG}g[@class='bar']")) == len(timeline.intervals)
    assert len(root.findall(f"{SVG}g[@class='release']")) == 1
    fills = [rect.get("fill") for rect in root.iter(f"{SVG}rect")]
    assert RED in fills and OLIVE in fills
    assert "mission <demo> & more" in "".join(root.itertext())


def test_png_through_imagemagick_or_a_clear_error(
    history: MissionHistory, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    if shutil.which("convert"):
        png = write_timeline(history.timeline(), tmp_path / "t.png", "demo")
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    monkeypatch.setattr(shutil, "which", lambda _name: None)
    with pytest.raises(TimelineExportError, match="PNG needs ImageMagick"):
        write_timeline(history.timeline(), tmp_path / "u.png")
    with pytest.raises(TimelineExportError, match=r"\.svg or \.png"):
        write_timeline(history.timeline(), tmp_path / "t.jpg")


# -- rosbag ------------------------------------------------------------------------------


def test_rosbag_holds_every_message_on_the_mission_clock(
    recording: Recording, tmp_path: Path
) -> None:
    journal = read_journal(recording.path)
    summary = journal_to_rosbag(recording.path, tmp_path / "mission.bag")
    expected: dict[str, int] = {}
    for record in journal.records:
        expected[record.topic] = expected.get(record.topic, 0) + 1
    assert summary.counts == expected
    assert set(expected) == {MISSION_TOPIC, EVENTS_TOPIC, ROBOT_REPORTS_TOPIC}
    # No TF here: the robots' report stamps are the clock, each report plays at its stamp.
    assert summary.clock == ROBOT_REPORTS_TOPIC
    clock = MissionClock.of(journal.records)
    with rosbag.Bag(str(summary.path)) as bag:
        info = bag.get_type_and_topic_info().topics
        assert {topic: info[topic].message_count for topic in info} == expected
        assert info[MISSION_TOPIC].msg_type == "rosmc/Mission"
        played = sorted(
            ((t.to_nsec(), topic, msg) for topic, msg, t in bag.read_messages()),
            key=lambda row: row[:2],
        )
        latched = {c.topic: c.header.get("latching") for c in bag._connections.values()}
    recorded = sorted(((clock.time_of(r), r.topic, r.message) for r in journal.records), key=_key)
    assert [(t, topic) for t, topic, _ in played] == [(t, topic) for t, topic, _ in recorded]
    assert [m.revision for t, topic, m in played if topic == EVENTS_TOPIC] == [
        m.revision for t, topic, m in recorded if topic == EVENTS_TOPIC
    ]
    reports = [(t, m) for t, topic, m in played if topic == ROBOT_REPORTS_TOPIC]
    assert reports and all(t == m.stamp.to_nsec() for t, m in reports)
    assert latched[MISSION_TOPIC] == b"1"


def _key(row: tuple[int, str, Any]) -> tuple[int, str]:
    return row[0], row[1]


# -- the command line, offline ---------------------------------------------------------


def test_cli_at_timeline_and_tobag_work_without_a_master(
    recording: Recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    journal = str(recording.path)
    assert rosmc(["at", journal, "r12"]) == 0
    assert "at r12 (revision 12)" in capsys.readouterr().out
    assert rosmc(["at", journal, f"{seconds(recording, 30):.3f}", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["revision"] == 30
    assert rosmc(["at", journal, "soon"]) == 2
    assert rosmc(["at", journal, "r999"]) == 1
    capsys.readouterr()
    assert rosmc(["at", journal, "9999"]) == 1  # past the end: refused, not the last revision
    assert "'9999' is outside the recording" in capsys.readouterr().err
    assert rosmc(["timeline", journal, "-o", str(tmp_path / "t.svg")]) == 0
    ET.parse(tmp_path / "t.svg")
    assert rosmc(["tobag", journal, str(tmp_path / "m.bag")]) == 0
    assert rosmc(["tobag", journal, str(tmp_path / "m.bag")]) == 1  # exists
    assert "messages" in capsys.readouterr().out


def test_history_and_pictures_do_not_import_rospy() -> None:
    program = (
        "import sys, rosmc_server.recording.history, rosmc_server.recording.timeline_svg; "
        "sys.exit('rospy' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr or "rospy was imported"


def test_a_server_on_wall_time_and_robots_on_sim_time_still_draw_right(tmp_path: Path) -> None:
    """The server started before /use_sim_time was set: its events carry wall time, the
    robots' reports sim time. The bars must still span what the robots did."""
    wall = iter(float(1_700_000_000 + n) for n in range(1000))
    mission = Mission(
        load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml"), clock=lambda: next(wall)
    )
    path = tmp_path / "mixed.mcap"
    with JournalWriter.create(path, mission_to_msg(mission.state.content(), 0, 0.0), T0) as writer:

        def journal(event: MissionEvent, second: float) -> None:
            state = mission.state
            msg = event_to_msg(event, lambda s: state.locate(s)[0])
            writer.append_event(msg, T0 + round(second * 1e9))

        added = mission.add_skill("drone", "take_off", {"altitude": 5.0})
        journal(added, 0.5)
        skill_id = added.change.put_skills[0].skill.id
        journal(mission.synchronize("drone"), 1.0)
        journal(mission.confirm_synchronized("drone", [skill_id]), 2.0)
        for status, sim_stamp, heard in ((S.RUNNING, 10.0, 10.2), (S.SUCCESS, 40.0, 40.3)):
            report = wire.RobotReport(
                agent="drone",
                stamp=genpy.Time.from_sec(sim_stamp),
                skill_id=skill_id,
                status=wire.SkillStatus(int(status)),
                attempt=1,
            )
            writer.append_report(report, T0 + round(heard * 1e9))
            journal(mission.report_status(skill_id, status, stamp=sim_stamp), heard)
    bar = MissionHistory.from_journal(path).timeline().lanes["drone"][0]
    assert (bar.start, bar.end) == pytest.approx((10.0, 40.0), abs=0.5)
    assert bar.outcome is S.SUCCESS
