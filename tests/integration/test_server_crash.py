"""kill -9 of the mission server loses no acknowledged change.

A client sends a few hundred mixed operations while the test keeps its own expected
mission: the mission core, fed with every acknowledged request (and the ids the server
chose), cross-checked against GetMission as it goes. The server is killed with SIGKILL
while a request is in flight, restarted on its journal with ``_resume:=true``, and the
restored mission must be exactly the last acknowledged one; only the request in flight
may or may not have landed, and then as exactly the next revision. A torn journal tail
(the last bytes of the file missing) is recovered to the last complete record. A damaged
byte in the middle costs the revisions it makes impossible to rebuild, said once as an ERROR
and in ``rosmc status``, and no revision number is handed out twice.
"""

from __future__ import annotations

import itertools
import json
import random
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest
import rosmc.msg as wire
import rospy
from mcap.reader import SeekingReader

pytest.register_assert_rewrite("tests.integration.server_fixtures")

from rosmc_server import interface  # noqa: E402
from rosmc_server.conversions import (  # noqa: E402
    marker_from_msg,
    mission_from_msg,
    mission_to_msg,
    params_from_msgs,
    pose_from_msg,
)
from rosmc_server.core import (  # noqa: E402
    Mission,
    MissionContent,
    RosmcError,
    dump_mission,
    load_library,
    parse_mission,
)
from rosmc_server.recording import latest_state, read_journal  # noqa: E402
from rosmc_server.recording._mcap import scan as _scan  # noqa: E402
from tests.integration.server_fixtures import REPO, Client, ServerProcess, mission_key  # noqa: E402

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

LIBRARY = load_library(REPO / "rosmc_server" / "config" / "mars_team.yaml")
PV = wire.ParameterValue
ROUNDS = 5
CROSS_CHECK_EVERY = 25


@dataclass
class Op:
    """One operator request: the service and the request's fields."""

    operation: str
    fields: dict[str, Any]


class Expected:
    """The expected mission: the core, given every acknowledged request in order."""

    def __init__(self, snapshot: wire.Mission) -> None:
        content, revision = mission_from_msg(snapshot)
        self._new_id = ""
        self.mission = Mission(LIBRARY, content, revision, clock=lambda: 0.0, new_id=self._id)

    def _id(self, prefix: str) -> str:
        return self._new_id

    @property
    def revision(self) -> int:
        return self.mission.revision

    def key(self) -> bytes:
        content = self.mission.state.content()
        return mission_key(mission_to_msg(content, self.mission.revision, 0.0))

    def apply(self, op: Op, new_id: str = "") -> None:
        """Apply ``op`` as the server does; RosmcError if the core refuses it."""
        self._new_id = new_id
        m, f = self.mission, op.fields
        base = f.get("base_revision")
        if op.operation == "add_skill":
            values, bindings = params_from_msgs(f.get("parameters", []))
            index = f.get("index", -1)
            m.add_skill(
                f["agent"],
                f["skill"],
                values,
                bindings=bindings,
                label=f.get("label", ""),
                index=None if index < 0 else index,
                timeout=f.get("timeout", 0.0),
                max_retries=f.get("max_retries", 0),
                base_revision=base,
            )
        elif op.operation == "edit_skill":
            values, bindings = params_from_msgs(f.get("parameters", []))
            options = f.get("set_options", False)
            m.edit_skill(
                f["skill_id"],
                values,
                bindings=dict(bindings),
                label=f.get("label") or None,
                timeout=f.get("timeout", 0.0) if options else None,
                max_retries=f.get("max_retries", 0) if options else None,
                base_revision=base,
            )
        elif op.operation == "delete_skills":
            m.delete_skills(f["skill_ids"], base_revision=base)
        elif op.operation == "reorder_skills":
            m.reorder(f["agent"], f["order"], base_revision=base)
        elif op.operation == "synchronize":
            m.synchronize(f["agent"], f.get("upto_id") or None, base_revision=base)
        elif op.operation == "add_barrier":
            m.add_barrier(f["skill_ids"], base_revision=base)
        elif op.operation == "delete_barrier":
            m.delete_barrier(f["barrier_id"], base_revision=base)
        elif op.operation == "add_task_marker":
            m.add_marker(marker_from_msg(f["marker"]), base_revision=base)
        elif op.operation == "move_task_marker":
            vertices = [pose_from_msg(v) for v in f.get("vertices", [])]
            m.move_marker(f["name"], pose_from_msg(f["pose"]), vertices, base_revision=base)
        elif op.operation == "load_mission":
            content, _ = parse_mission(f["document"], LIBRARY, "the document")
            m.load(content, "a document", base_revision=base)
        else:
            raise AssertionError(op.operation)


# -- random operations on the expected mission -------------------------------------------------
WEIGHTS = {
    "add_skill": 34,
    "edit_skill": 20,
    "delete_skills": 10,
    "reorder_skills": 8,
    "add_task_marker": 4,
    "move_task_marker": 9,
    "add_barrier": 6,
    "delete_barrier": 4,
    "synchronize": 5,
}


def editable(expected: Expected, agent: str) -> list[str]:
    state = expected.mission.state
    return [s.id for s in state.task(agent)[state.sections(agent).editable_start :]]


def random_op(rng: random.Random, expected: Expected) -> Op:
    """A plausible request against the expected mission (some are refused, on purpose)."""
    state = expected.mission.state
    agents = list(state.agents)
    base = {"base_revision": expected.revision}
    kind = rng.choices(list(WEIGHTS), weights=list(WEIGHTS.values()))[0]
    blueprints = {a: editable(expected, a) for a in agents}
    with_skills = [a for a in agents if blueprints[a]]
    markers = [m.name for m in state.markers]
    if kind == "add_skill" or not with_skills:
        agent = rng.choice(agents)
        skill = rng.choice(sorted(LIBRARY.skills_of(agent)))
        params = []
        for spec in LIBRARY.skill(agent, skill).parameters:
            if spec.type == PV.FLOAT and spec.minimum is not None and rng.random() < 0.5:
                value = rng.uniform(spec.minimum, spec.maximum or spec.minimum + 10)
                params.append(PV(name=spec.name, type=PV.FLOAT, float_value=value))
            elif spec.marker_type is not None and spec.type == PV.POSE and markers:
                params.append(PV(name=spec.name, type=PV.POSE, marker=rng.choice(markers)))
        index = rng.choice([-1, -1, len(state.task(agent))])
        return Op(
            "add_skill",
            {
                **base,
                "agent": agent,
                "skill": skill,
                "index": index,
                "parameters": params,
                "label": rng.choice(["", f"L{rng.random():.6f}"]),
            },
        )
    agent = rng.choice(with_skills)
    ids = blueprints[agent]
    if kind == "edit_skill":
        return Op(
            "edit_skill",
            {
                **base,
                "skill_id": rng.choice(ids),
                "label": f"e{rng.random():.9f}",
                "set_options": rng.random() < 0.3,
                "timeout": rng.uniform(0, 100),
                "max_retries": rng.randrange(5),
            },
        )
    if kind == "delete_skills":
        return Op(
            "delete_skills",
            {**base, "skill_ids": rng.sample(ids, min(len(ids), rng.choice([1, 1, 2])))},
        )
    if kind == "reorder_skills":
        order = list(ids)
        rng.shuffle(order)
        return Op("reorder_skills", {**base, "agent": agent, "order": order})
    if kind == "add_task_marker":
        pose = wire.Pose6D(x=rng.uniform(-50, 50), y=rng.uniform(-50, 50), yaw=rng.uniform(-3, 3))
        return Op(
            "add_task_marker",
            {**base, "marker": wire.TaskMarker(name=f"M{rng.random():.8f}", type=1, pose=pose)},
        )
    if kind == "move_task_marker" and markers:
        pose = wire.Pose6D(x=rng.uniform(-50, 50), y=rng.uniform(-50, 50))
        return Op("move_task_marker", {**base, "name": rng.choice(markers), "pose": pose})
    if kind == "add_barrier" and len(with_skills) >= 2:
        members = [rng.choice(blueprints[a]) for a in rng.sample(with_skills, 2)]
        return Op("add_barrier", {**base, "skill_ids": members})
    if kind == "delete_barrier" and state.barriers:
        return Op("delete_barrier", {**base, "barrier_id": rng.choice(state.barriers).id})
    if kind == "synchronize":
        upto = rng.choice(ids[:3])
        return Op("synchronize", {**base, "agent": agent, "upto_id": upto})
    return Op("edit_skill", {**base, "skill_id": rng.choice(ids), "label": f"x{rng.random():.9f}"})


def new_id(op: Op, response: Any) -> str:
    return str(getattr(response, "skill_id", "") or getattr(response, "barrier_id", ""))


# -- one round: operate, get killed, come back --------------------------------------------------
@dataclass
class Session:
    """What a client saw in one round."""

    acknowledged: int = 0
    in_flight: Op | None = None
    refused: int = 0
    cross_checks: int = 0
    error: BaseException | None = None
    history: dict[int, bytes] = field(default_factory=dict)


def operate(
    client: Client,
    expected: Expected,
    rng: random.Random,
    count: int,
    kill_at: int,
    at_kill_point: threading.Event,
    session: Session,
    keep_history: bool = False,
    choose: Callable[[random.Random, Expected], Op] = random_op,
) -> None:
    """Send ``count`` operations; until the server dies, keep ``expected`` in step."""
    try:
        for number in range(count):
            op = choose(rng, expected)
            if number == kill_at:
                at_kill_point.set()
            session.in_flight = op
            try:
                response = client.call(op.operation, **op.fields)
            except (rospy.ServiceException, rospy.ROSException, OSError):
                # The server died with this request in flight, or before the first request
                # of its kind found the service (wait_for_service timed out: a ROSException).
                return
            session.in_flight = None
            if response.error_code != wire.ErrorCode.NONE:
                session.refused += 1
                assert response.error_code != wire.ErrorCode.INTERNAL, response.error
                with pytest.raises(RosmcError):  # the core refuses it too, unchanged
                    expected.apply(op)
                continue
            expected.apply(op, new_id(op, response))
            assert response.revision == expected.revision, (op, response)
            session.acknowledged += 1
            if keep_history:
                session.history[expected.revision] = expected.key()
            if number % CROSS_CHECK_EVERY == 0:
                try:
                    mission = client.mission()
                except (rospy.ServiceException, OSError):
                    return
                assert mission_key(mission) == expected.key(), f"diverged after {op}"
                session.cross_checks += 1
    except BaseException as error:
        session.error = error
    finally:
        at_kill_point.set()


def restored_matches(expected: Expected, session: Session, mission: wire.Mission) -> str:
    """Check the restarted server's mission against the expectation; how it matched."""
    if mission.revision == expected.revision:
        assert mission_key(mission) == expected.key(), "an acknowledged change was lost"
        return "last acknowledged"
    op = session.in_flight
    assert op is not None, f"revision {mission.revision}, acknowledged {expected.revision}"
    assert mission.revision == expected.revision + 1, (mission.revision, expected.revision)
    chosen = ""
    if op.operation == "add_skill":
        known = {s.id for s in expected.mission.state.skills()}
        chosen = next(s.id for t in mission.tasks for s in t.skills if s.id not in known)
    elif op.operation == "add_barrier":
        known = {b.id for b in expected.mission.state.barriers}
        chosen = next(b.id for b in mission.barriers if b.id not in known)
    expected.apply(op, chosen)
    assert mission_key(mission) == expected.key(), "the change in flight landed wrongly"
    return "in-flight change landed"


def test_kill_9_loses_no_acknowledged_change(
    start_server: Callable[..., ServerProcess], tmp_path: Path
) -> None:
    journal = tmp_path / "crash.mcap"
    rng = random.Random(20261122)
    server = start_server("crash", journal=journal)
    with Client() as client:
        # A mission replacement first: its content lives only in a journal snapshot.
        document = _seed_document(client)
        response = client.call("load_mission", base_revision=client.revision(), document=document)
        assert response.error_code == 0, response.error
        expected = Expected(client.mission())
    outcomes = []
    for round_number in range(ROUNDS):
        with Client() as client:
            assert mission_key(client.mission()) == expected.key()
            session = Session()
            at_kill_point = threading.Event()
            kill_at = rng.randrange(120, 280)
            worker = threading.Thread(
                target=operate,
                args=(client, expected, rng, 400, kill_at, at_kill_point, session),
            )
            worker.start()
            assert at_kill_point.wait(60)
            time.sleep(rng.uniform(0, 0.001))
            server.kill9()
            worker.join(60)
            assert not worker.is_alive()
            if session.error is not None:
                raise session.error
            assert session.acknowledged >= 100 and session.cross_checks >= 3, session
        server = start_server("crash", journal=journal, resume=True)
        with Client() as client:
            outcomes.append(restored_matches(expected, session, client.mission()))
        assert "Traceback" not in server.log(), server.log()[-3000:]
        print(
            f"round {round_number}: {session.acknowledged} acknowledged, "
            f"{session.refused} refused, {outcomes[-1]}"
        )
    with Client() as client:
        final = client.mission()
    assert mission_key(final) == expected.key()
    assert sum(len(t.skills) for t in final.tasks) > 100


def _seed_document(client: Client) -> str:
    """A saved mission with a few skills and a marker, as a document to load."""
    rev = client.revision()
    marker = wire.TaskMarker(name="Base", type=1, pose=wire.Pose6D(x=1, y=2))
    rev = client.call("add_task_marker", base_revision=rev, marker=marker).revision
    for agent, skill in (("drone", "take_off"), ("science_rover", "explore")):
        rev = client.call(
            "add_skill", base_revision=rev, agent=agent, skill=skill, index=-1
        ).revision
    document = str(client.call("save_mission").document)
    client.call("new_mission", base_revision=rev, keep_markers=False)
    return document


def large_document(tag: str, skills: int) -> str:
    """A saved mission of ``skills`` blueprint skills over every robot (default parameters)."""
    counter = iter(range(10**9))
    empty = MissionContent.empty(LIBRARY)
    mission = Mission(LIBRARY, empty, new_id=lambda prefix: f"{tag}-{next(counter)}")
    agents = LIBRARY.dynamic_agents
    for number in range(skills):
        agent = agents[number % len(agents)]
        names = sorted(LIBRARY.skills_of(agent))
        mission.add_skill(agent, names[number % len(names)], {}, label=f"{tag} {number}")
    return dump_mission(mission.state.content(), 0)


def loads_and_changes(documents: list[str], kill_at: int) -> Callable[[Any, Expected], Op]:
    """Operations for :func:`operate`: a load every few, and always at the kill point."""
    chosen = itertools.count()

    def choose(rng: random.Random, expected: Expected) -> Op:
        if next(chosen) == kill_at or rng.random() < 0.3:
            fields = {"base_revision": expected.revision, "document": rng.choice(documents)}
            return Op("load_mission", fields)
        while (op := random_op(rng, expected)).operation == "synchronize":
            pass  # an upload would keep every later load refused (no robot answers)
        return op

    return choose


def test_kill_9_around_loads_of_large_missions(
    start_server: Callable[..., ServerProcess], tmp_path: Path
) -> None:
    """A load is acknowledged only once its mission is durable; kill -9 lands inside loads."""
    journal = tmp_path / "loads.mcap"
    rng = random.Random(20261124)
    documents = [large_document("a", 1500), large_document("b", 1800)]
    server = start_server("loads", journal=journal)
    with Client() as client:
        expected = Expected(client.mission())
    outcomes = []
    for _ in range(3):
        kill_at = rng.randrange(8, 30)
        with Client() as client:
            session = Session()
            at_kill_point = threading.Event()
            worker = threading.Thread(
                target=operate,
                args=(client, expected, rng, 200, kill_at, at_kill_point, session),
                kwargs={"choose": loads_and_changes(documents, kill_at)},
            )
            worker.start()
            assert at_kill_point.wait(120)
            time.sleep(rng.uniform(0, 0.1))  # a load of 1,500 skills takes longer than that
            server.kill9()
            worker.join(120)
            assert not worker.is_alive()
            if session.error is not None:
                raise session.error
        in_flight = session.in_flight.operation if session.in_flight else "nothing"
        server = start_server("loads", journal=journal, resume=True)
        with Client() as client:
            outcomes.append((in_flight, restored_matches(expected, session, client.mission())))
        assert "Traceback" not in server.log(), server.log()[-3000:]
    print("killed with in flight / restored as:", outcomes)
    assert any(skill.id.startswith(("a-", "b-")) for skill in expected.mission.state.skills())


# -- torn journal tails ------------------------------------------------------------------------
MAGIC = b"\x89MCAP0\r\n"
CHUNK, MESSAGE_INDEX = 0x06, 0x07


def records(data: bytes) -> list[tuple[int, int, int]]:
    """(offset, opcode, total length) of each complete MCAP record after the magic."""
    assert data.startswith(MAGIC)
    found, offset = [], len(MAGIC)
    while offset + 9 <= len(data):
        opcode, length = struct.unpack_from("<BQ", data, offset)
        if offset + 9 + length > len(data):
            break
        found.append((offset, opcode, 9 + length))
        offset += 9 + length
    return found


@pytest.mark.parametrize("cut", ["index", "chunk"])
def test_a_torn_journal_tail_is_dropped_with_a_warning(
    start_server: Callable[..., ServerProcess], tmp_path: Path, cut: str
) -> None:
    journal = tmp_path / "torn.mcap"
    server = start_server("torn", journal=journal)
    rng = random.Random(7 if cut == "index" else 8)
    with Client() as client:
        expected = Expected(client.mission())
        session = Session()
        operate(client, expected, rng, 80, -1, threading.Event(), session, keep_history=True)
        assert session.error is None and session.in_flight is None, session
    last = expected.revision
    server.kill9()
    data = journal.read_bytes()
    layout = records(data)
    assert sum(length for _, _, length in layout) + len(MAGIC) == len(data), "torn before cut"
    _, opcode, _ = layout[-1]
    assert opcode == MESSAGE_INDEX, "each journal append ends with its chunk's message index"
    chunk_offset, chunk_opcode, chunk_length = layout[-2]
    assert chunk_opcode == CHUNK
    if cut == "index":  # the chunk itself stays complete
        size, intact, survivor = len(data) - 3, chunk_offset + chunk_length, last
    else:
        size, intact, survivor = chunk_offset + chunk_length - 5, chunk_offset, last - 1
    with journal.open("r+b") as handle:
        handle.truncate(size)
    server = start_server("torn", journal=journal, resume=True)
    assert f"dropped the last {size - intact} bytes" in server.log(), server.log()[-2000:]
    assert list(tmp_path.glob("torn.mcap.dropped-*")), "the dropped tail was not kept"
    errors = [line for line in server.log().splitlines() if "[ERROR]" in line]
    with Client() as client:
        mission = client.mission()
        if survivor == last:
            assert mission.revision == survivor and not errors
        else:  # an acknowledged change was cut off: a loss, said as one (revision mark)
            assert len(errors) == 1 and f"r{last} lost from its end" in errors[0], errors
            assert mission.revision > last  # a new revision: r{last} is never handed out again
        expected = Expected(mission)
        mission.revision = survivor
        assert mission_key(mission) == session.history[survivor]
        # The journal goes on after the cut: more changes, another crash, all there.
        more = Session()
        operate(client, expected, rng, 30, -1, threading.Event(), more)
        assert more.error is None and more.acknowledged > 0
    server.kill9()
    start_server("torn", journal=journal, resume=True)
    with Client() as client:
        assert mission_key(client.mission()) == expected.key()


# -- a damaged journal -------------------------------------------------------------------------
def test_a_damaged_journal_resumes_loudly_and_never_hands_out_a_revision_again(
    start_server: Callable[..., ServerProcess], tmp_path: Path
) -> None:
    journal = tmp_path / "damaged.mcap"
    server = start_server("damaged", journal=journal)
    with Client() as client:
        expected = Expected(client.mission())
        session = Session()
        operate(client, expected, random.Random(11), 80, -1, threading.Event(), session, True)
        assert session.error is None and session.in_flight is None, session
    last = expected.revision
    server.kill9()
    middle = last // 2
    start, end = _event_chunk(journal, middle)
    data = bytearray(journal.read_bytes())
    data[(start + end) // 2] ^= 0x08  # one bit, inside the chunk of revision `middle`
    journal.write_bytes(bytes(data))

    server = start_server("damaged", journal=journal, resume=True)
    errors = [line for line in server.log().splitlines() if "[ERROR]" in line]
    assert len(errors) == 1, errors
    assert f"skipped damaged bytes {start}.." in errors[0]
    lost = f"r{middle}..r{last}"
    assert f"{last - middle + 1} revisions {lost} cannot be rebuilt" in errors[0]
    assert f"the mission resumed at r{middle - 1}, next revision r{last + 1}" in errors[0]
    alert = (
        f"journal: {last - middle + 1} revisions lost at resume ({lost}: the mission resumed "
        f"at r{middle - 1}, next revision r{last + 1}), see {journal}"
    )
    status = _rosmc(server, "status", "--no-states")
    assert status.splitlines()[0] == alert
    assert json.loads(_rosmc(server, "--json", "status", "--no-states"))["journal_alert"] == alert
    with Client() as client:
        mission = client.mission()
        # The resumed mission is a revision of its own, above every one the operators saw...
        assert mission.revision == last + 1
        mission.revision = middle - 1
        assert mission_key(mission) == session.history[middle - 1]  # ...the content is r-1's
        marker = wire.TaskMarker(name="After", type=1, pose=wire.Pose6D(x=1.0))
        stale = client.call("add_task_marker", base_revision=last, marker=marker)
        assert stale.error_code == wire.ErrorCode.CONFLICT  # a view of lost changes is stale
        rev = client.call("add_task_marker", base_revision=last + 1, marker=marker).revision
        assert rev == last + 2
    assert server.stop() == 0  # a clean stop closes the new part with its summary
    part = tmp_path / "damaged.part002.mcap"
    with part.open("rb") as file:  # the mcap package reads it: a valid, indexed MCAP file
        found = [m.log_time for _, _, m in SeekingReader(file, validate_crcs=True).iter_messages()]
    assert len(found) >= 2  # the resume's snapshot (r{last + 1}) and the new change
    result = read_journal(journal)  # the whole journal, both files
    assert result.files == (journal, part) and len(result.damage) == 1
    state = latest_state(result)
    assert state.revision == last + 2 and state.next_revision == last + 3
    assert [str(gap.revisions) for gap in state.gaps] == [f"r{middle}..r{last}"]


def _event_chunk(journal: Path, revision: int) -> tuple[int, int]:
    """The bytes of the chunk that holds the event of ``revision``."""
    scan = _scan.scan(journal)
    events = next(c.id for c in scan.channels.values() if c.topic == interface.EVENTS_TOPIC)
    for message, span in zip(scan.messages, scan.spans, strict=True):
        if message.channel_id == events and int.from_bytes(message.data[:8], "little") == revision:
            return span
    raise AssertionError(f"no event of revision {revision} in {journal}")


def _rosmc(server: ServerProcess, *args: str) -> str:
    """Run the ``rosmc`` command against the test's master; its standard output."""
    done = subprocess.run(
        [sys.executable, str(REPO / "scripts" / "rosmc"), *args],
        env=server.env,
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    return done.stdout
