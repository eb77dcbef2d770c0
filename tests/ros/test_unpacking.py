"""Snapshots read straight from wire bytes equal what genpy and ``mission_from_msg`` make.

:mod:`rosmc_server.conversions.unpacking` reads a ``rosmc/Mission`` (and a GetMission answer)
into core objects without genpy messages. A client must not be able to tell: every skill
of a random 10,000-skill mission (every status, parameter type and binding, tricky text and
numbers), barriers and markers come out equal; undecodable text is replaced as genpy
replaces it; bytes that end early or run on fail as malformed, and numbers no mission can
hold fail with the sentence ``mission_from_msg`` gives.
"""

from __future__ import annotations

import random
import struct

import genpy
import pytest
import rosmc.msg as wire
import rosmc.srv as srv

from rosmc_server.conversions import mission_from_msg, mission_to_msg, skill_to_msg, unpacking
from rosmc_server.conversions.packing import (
    PackedGetMissionResponse,
    SnapshotPacker,
    serialized,
)
from rosmc_server.conversions.unpacking import (
    UNPACKED_MISSION_MD5,
    UnpackedGetMission,
    UnpackedGetMissionResponse,
    mission_from_bytes,
)
from rosmc_server.core import (
    InvalidRequest,
    Library,
    MissionContent,
    Pose,
    SkillInstance,
    SkillStatus,
    Transfer,
)
from rosmc_server.core.skills.library import library_from_dict
from tests.unit.conftest import TEST_LIBRARY
from tests.unit.random_missions import random_content


@pytest.fixture(scope="module")
def library() -> Library:
    return library_from_dict(TEST_LIBRARY)


def genpy_read(data: bytes) -> tuple[MissionContent, int]:
    """What a client made of the bytes before: genpy messages, then ``mission_from_msg``."""
    return mission_from_msg(wire.Mission().deserialize(data))


def test_the_direct_reader_is_in_use() -> None:
    # A changed rosmc/Mission definition falls back to genpy; this test then asks for an update.
    assert wire.Mission._md5sum == UNPACKED_MISSION_MD5
    assert UnpackedGetMission._md5sum == srv.GetMission._md5sum
    assert UnpackedGetMission._type == srv.GetMission._type


def test_a_random_mission_reads_as_genpy_and_the_conversion_read_it(library: Library) -> None:
    content = random_content(library, 10_000, seed=31)
    assert content.barriers and content.markers
    data = serialized(SnapshotPacker().pack(content, 4242, 1732435200.5))
    read, revision, end = mission_from_bytes(data)
    assert (read, revision) == genpy_read(data)
    assert read == content and revision == 4242 and end == len(data)
    for task in read.tasks.values():  # the same types, not only equal values
        for skill in task:
            assert all(
                type(v) is type(skill_value(content, skill, k)) for k, v in skill.params.items()
            )


def skill_value(content: MissionContent, skill: SkillInstance, name: str) -> object:
    original = next(s for s in content.tasks[skill.agent] if s.id == skill.id)
    return original.params[name]


def test_a_mission_read_from_an_offset_says_where_it_ends(library: Library) -> None:
    content = random_content(library, 50, seed=32)
    data = serialized(mission_to_msg(content, 9, 0.0))
    read, revision, end = mission_from_bytes(b"head" + data + b"tail", 4)
    assert (read, revision, end) == (content, 9, 4 + len(data))


def test_a_get_mission_answer_reads_into_core_objects(library: Library) -> None:
    content = random_content(library, 300, seed=33)
    packed = SnapshotPacker().pack(content, 17, 1.0)
    alert = "3 revisions lost at resume (r4..r6)"
    data = serialized(PackedGetMissionResponse(packed, alert, "3f9a01c2"))
    answer = UnpackedGetMissionResponse().deserialize(data)
    assert (answer.content, answer.revision) == (content, 17)
    assert (answer.journal_alert, answer.epoch) == (alert, "3f9a01c2")
    assert answer.mission == wire.Mission()  # no genpy copy kept beside the core one


def test_without_the_definition_it_was_written_for_it_reads_through_genpy(
    library: Library, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(unpacking, "UNPACKED_MISSION_MD5", "0" * 32)
    content = random_content(library, 200, seed=34)
    data = serialized(srv.GetMissionResponse(mission_to_msg(content, 5, 0.0), "alert", "e1"))
    answer = UnpackedGetMissionResponse().deserialize(data)
    assert (answer.content, answer.revision, answer.journal_alert) == (content, 5, "alert")
    assert answer.epoch == "e1"


def one_skill_mission(**fields: object) -> bytes:
    skill = skill_to_msg(SkillInstance("s1", "alpha", "move", "move", {"speed": 1.5}))
    for name, value in fields.items():
        setattr(skill, name, value)
    mission = wire.Mission(revision=3, library="lib", tasks=[wire.AgentTask("alpha", [skill])])
    return serialized(mission)


def test_undecodable_text_is_replaced_as_genpy_replaces_it() -> None:
    data = one_skill_mission(label="m?ve")
    broken = data.replace(b"m?ve", b"m\xffve")
    assert broken != data
    read, _, _ = mission_from_bytes(broken)
    assert (read, 3) == genpy_read(broken)
    assert read.tasks["alpha"][0].label == "m\ufffdve"


@pytest.mark.parametrize(
    ("fields", "sentence"),
    [
        ({"status": wire.SkillStatus(9)}, "unknown status number 9"),
        ({"transfer": 7}, "unknown transfer number 7"),
        ({"resolution": 5}, "unknown resolution number 5"),
        ({"parameters": [wire.ParameterValue(name="", type=2)]}, "empty name"),
        ({"parameters": [wire.ParameterValue(name="p", type=12)]}, "unknown type number 12"),
        ({"parameters": [wire.ParameterValue(name="p", type=4, json_value="{")]}, "valid JSON"),
        ({"parameters": [wire.ParameterValue(name="p", type=5, json_value="[1]")]}, "JSON dict"),
    ],
)
def test_what_no_mission_holds_fails_as_the_conversion_says(
    fields: dict[str, object], sentence: str
) -> None:
    data = one_skill_mission(**fields)
    with pytest.raises(InvalidRequest, match=sentence) as direct:
        mission_from_bytes(data)
    with pytest.raises(InvalidRequest) as converted:
        genpy_read(data)
    assert str(direct.value) == str(converted.value)


def test_every_parameter_type_and_a_binding_read_back() -> None:
    values = {"b": True, "i": -(2**63), "f": -0.0, "s": "😀 text", "l": [1, {"a": None}], "d": {}}
    skill = SkillInstance(
        "s1", "alpha", "move", "move", {**values, "p": Pose(1.0, 2.0, 3.0, 0.1, 0.2, 0.3)},
        bindings={"p": "rock_7"},
    )  # fmt: skip
    content = MissionContent("lib", {"alpha": [skill]}, {}, {})
    read, _, _ = mission_from_bytes(serialized(mission_to_msg(content, 1, 0.0)))
    assert read == content
    assert str(read.tasks["alpha"][0].params["f"]) == "-0.0"


def test_bytes_that_end_early_fail_as_malformed(library: Library) -> None:
    content = random_content(library, 12, seed=35)
    data = serialized(PackedGetMissionResponse(SnapshotPacker().pack(content, 2, 0.0), "x"))
    for cut in range(len(data)):
        with pytest.raises(genpy.DeserializationError):
            UnpackedGetMissionResponse().deserialize(data[:cut])


def test_bytes_after_the_answer_fail_as_malformed(library: Library) -> None:
    data = serialized(
        PackedGetMissionResponse(SnapshotPacker().pack(MissionContent.empty(library), 1, 0.0))
    )
    with pytest.raises(genpy.DeserializationError, match="1 bytes after"):
        UnpackedGetMissionResponse().deserialize(data + b"\x00")


def test_a_huge_count_fails_quickly_as_malformed() -> None:
    data = bytearray(one_skill_mission())
    count_at = 8 + 8 + 4 + len(b"lib")  # revision, stamp, library
    data[count_at : count_at + 4] = struct.pack("<I", 2**32 - 1)
    with pytest.raises(genpy.DeserializationError):
        mission_from_bytes(bytes(data))


@pytest.mark.parametrize(
    "param",
    [
        wire.ParameterValue(name="s", type=3, string_value="abc"),
        wire.ParameterValue(name="s", type=3, string_value=""),
        wire.ParameterValue(name="s", type=3, string_value="abc", marker="m1"),
        wire.ParameterValue(name="s", type=3, string_value="é", json_value="[1]"),
        wire.ParameterValue(name="s", type=3, json_value="[1]", marker="m1"),
        wire.ParameterValue(name="f", type=2, float_value=0.5, string_value="x"),
    ],
    ids=["text", "empty", "bound", "text-and-json", "json-only", "float-beside-text"],
)
def test_text_parameters_in_any_form_read_as_the_conversion_reads_them(
    param: wire.ParameterValue,
) -> None:
    data = one_skill_mission(parameters=[param, wire.ParameterValue(name="g", type=2)])
    read, _, end = mission_from_bytes(data)
    assert (read, 3) == genpy_read(data)
    assert end == len(data)


def test_repeated_parameters_read_as_genpy_reads_them_and_are_shared() -> None:
    # Parameter blocks that repeat, differ only at their end, differ in count or binding,
    # and runs of blocks never seen before (beta's longer than the reader keeps looking),
    # in a random order of two skill names.
    rng = random.Random(36)
    pose = Pose(1.0, 2.0, 0.0, 0.0, 0.0, 0.5)
    pool: list[tuple[dict[str, object], dict[str, str]]] = [
        ({"target": pose, "speed": 0.8}, {}),
        ({"target": pose, "speed": 0.9}, {}),
        ({"target": pose}, {}),
        ({"target": pose, "speed": 0.8}, {"target": "rock_1"}),
        ({"target": pose, "speed": 0.8, "mode": "quick"}, {}),
    ]

    def task(agent: str, new_run: int) -> list[SkillInstance]:
        skills = []
        for number in range(600):
            params, bindings = rng.choice(pool)
            if 200 <= number < 200 + new_run:
                params = {"target": pose, "speed": float(number)}
            name = rng.choice(["move", "drive"])
            skills.append(SkillInstance(f"{agent}{number}", agent, name, "x", params, bindings))
        return skills

    tasks = {"alpha": task("alpha", 40), "beta": task("beta", 100)}
    content = MissionContent("lib", tasks, {}, {})
    data = serialized(mission_to_msg(content, 8, 0.0))
    read, revision, _ = mission_from_bytes(data)
    assert (read, revision) == genpy_read(data)
    assert read == content
    alpha = read.tasks["alpha"]
    # One dict per distinct block of parameters and binding, however often it comes.
    assert len({id(skill.params) for skill in alpha[300:]}) == len(pool)
    assert len({id(skill.agent) for skill in alpha}) == 1


@pytest.mark.parametrize("seed", range(6))
def test_records_whose_rest_repeats_or_not_read_as_genpy_reads_them(seed: int) -> None:
    # The reader takes a record's rest (parameters, numbers, status text, times) from the
    # last record of its kind when the bytes match, and numbers from any record before:
    # rests that repeat, differ in one number, a sign, a status text or a time, records
    # whose agent is not their task's, in a random order, must read as genpy reads them.
    rng = random.Random(seed)
    statuses = list(SkillStatus)
    rests: list[dict[str, object]] = [
        {},
        {"status": SkillStatus.SUCCESS, "started": 1.5, "finished": 2.5},
        {"status": SkillStatus.SUCCESS, "started": 1.5, "finished": -0.0},
        {"status": SkillStatus.FAILURE, "status_text": "stuck", "attempt": 2},
        {"status": SkillStatus.FAILURE, "status_text": "stück", "attempt": 2},
        {"status": SkillStatus.IDLE_SYNCHRONIZED, "transfer": Transfer.UPLOADING},
        {"timeout": 30.0, "max_retries": 3},
    ]
    pool = [{"seconds": 5.0}, {"seconds": 5.0, "note": "x"}, {"seconds": -0.0}, {}]

    def task(agent: str) -> list[SkillInstance]:
        skills = []
        for number in range(400):
            rest = dict(rng.choice(rests))
            if rng.random() < 0.1:  # numbers never seen before
                rest.update(status=rng.choice(statuses), started=rng.random())
            owner = agent if rng.random() < 0.95 else "gamma"
            name = rng.choice(["wait", "move", "w"])
            label = "x" * rng.randrange(4)
            params = rng.choice(pool)
            skill = SkillInstance(f"{agent}{number}", owner, name, label, params, **rest)  # type: ignore[arg-type]
            skills.append(skill)
        return skills

    content = MissionContent("lib", {"alpha": task("alpha"), "beta": task("beta")}, {}, {})
    data = serialized(mission_to_msg(content, 5, 0.0))
    read, revision, end = mission_from_bytes(data)
    assert (read, revision) == genpy_read(data)
    assert read == content and end == len(data)
    for task_read, task_made in zip(read.tasks.values(), content.tasks.values(), strict=True):
        assert [repr(s) for s in task_read] == [repr(s) for s in task_made]  # -0.0 stays
