"""Mission files: versioned YAML that round-trips exactly and refuses anything malformed."""

from __future__ import annotations

import copy
import os
import stat
from pathlib import Path
from typing import Any

import pytest
import yaml

from rosmc_server.core import (
    InvalidRequest,
    Library,
    MarkerType,
    Mission,
    MissionContent,
    MissionFileError,
    Pose,
    SkillStatus,
    TaskMarker,
    dump_mission,
    load_mission,
    mission_to_dict,
    parse_mission,
    save_mission,
)
from rosmc_server.core.documents import durable
from rosmc_server.core.files.persistence import mission_from_dict

S = SkillStatus


@pytest.fixture
def rich(mission: Any, drv: Any, clock: Any) -> Any:
    """A mission that uses every feature a file has to carry."""
    mission.add_marker(TaskMarker("goal", MarkerType.POSE, Pose(1.0, 2.0, 0.0, 0.0, 0.0, 0.3)))
    mission.add_marker(TaskMarker("spot", MarkerType.POSITION, Pose(3.0, 4.0)))
    mission.add_marker(
        TaskMarker("field", MarkerType.AREA, Pose(), (Pose(0, 0), Pose(4, 0), Pose(4, 4)))
    )
    done = drv.add("alpha", "move", bindings={"target": "goal"}, label="first leg")
    failed = drv.add("alpha", "scan", {"passes": 3, "mode": "slow"}, bindings={"area": "field"})
    drv.add("alpha", "wait", {"options": {"k": [1, 2.5, None, "x"]}, "note": "ünïcode"})
    removing = drv.add("alpha", "wait", {"seconds": 4}, timeout=12.5, max_retries=2)
    drv.add("alpha", "noop", label="blueprint")
    drv.sync("alpha", removing)
    clock.now = 100.0
    drv.finish(done)
    clock.now = 110.0
    mission.report_status(failed, S.RUNNING, text="scanning")
    mission.report_status(failed, S.FAILURE, attempt=2, text="blocked")
    mission.retry(failed)
    mission.unsynchronize("alpha", removing)
    b1, b2 = drv.add("bravo", "scan", bindings={"point": "spot"}), drv.add("bravo", "move")
    c1 = drv.add("charlie")
    mission.add_barrier([b2, c1])
    drv.sync("bravo", b1)
    mission.report_status(b1, S.SYNCWAITING)
    mission.synchronize("bravo")
    skipped = drv.add("charlie", "noop", index=0)
    drv.sync("charlie", skipped)
    drv.finish(skipped, S.FAILURE)
    mission.skip(skipped)
    return mission


def test_save_and_load_reproduce_the_mission(rich: Any, tmp_path: Path, library: Any) -> None:
    path = tmp_path / "mission.yaml"
    content = rich.state.content()
    save_mission(path, content, rich.revision)
    loaded, revision = load_mission(path, library)
    assert revision == rich.revision
    assert loaded == content
    assert dump_mission(loaded, revision) == path.read_text(encoding="utf-8")
    assert mission_to_dict(loaded, revision) == mission_to_dict(content, rich.revision)


def test_file_is_versioned_plain_yaml(rich: Any, tmp_path: Path) -> None:
    path = tmp_path / "mission.yaml"
    save_mission(path, rich.state.content(), rich.revision)
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    assert data["rosmc_mission"] == 1
    assert data["library"] == "unit_team"
    assert [m["name"] for m in data["markers"]] == ["goal", "spot", "field"]
    assert "!!" not in path.read_text(encoding="utf-8")


def test_empty_mission_round_trips(mission: Any, library: Any) -> None:
    text = dump_mission(mission.state.content(), 0)
    assert parse_mission(text, library, "x") == (mission.state.content(), 0)


def test_minimal_file_takes_defaults(library: Any) -> None:
    text = "rosmc_mission: 1\nlibrary: unit_team\nrevision: 3\ntasks:\n  alpha:\n"
    text += "  - {id: a, skill: move, params: {speed: 1.5, target: {x: 1}}}\n"
    content, revision = parse_mission(text, library, "x")
    (skill,) = content.tasks["alpha"]
    assert revision == 3 and content.tasks["bravo"] == []
    assert (skill.label, skill.status, skill.attempt) == ("move", S.IDLE, 1)
    assert skill.params == {"speed": 1.5, "target": Pose(1.0)}


def test_loaded_mission_is_usable(
    rich: Any, tmp_path: Path, library: Any, new_mission_factory: Any
) -> None:
    path = tmp_path / "m.yaml"
    save_mission(path, rich.state.content(), rich.revision)
    other = new_mission_factory()
    other.load(*load_mission(path, library)[:1], str(path))
    # Everything that the robots held is back in the blueprint and can be synchronized.
    other.synchronize("alpha")
    other.synchronize("bravo")


def test_save_is_atomic(rich: Any, tmp_path: Path, monkeypatch: Any) -> None:
    path = tmp_path / "mission.yaml"
    save_mission(path, rich.state.content(), 1)
    old = path.read_text(encoding="utf-8")
    assert [p.name for p in tmp_path.iterdir()] == ["mission.yaml"]

    def no_space(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(durable.os, "fsync", no_space)  # the new file never reaches the disk
    with pytest.raises(MissionFileError, match="No space left") as caught:
        save_mission(path, rich.state.content(), 2)
    assert str(path) in str(caught.value) and "\n" not in str(caught.value)
    monkeypatch.undo()
    # The target still holds the complete previous save, and nothing else is left behind.
    assert path.read_text(encoding="utf-8") == old
    assert [p.name for p in tmp_path.iterdir()] == ["mission.yaml"]


def test_save_survives_a_power_loss(rich: Any, tmp_path: Path, monkeypatch: Any) -> None:
    """The new file is on the disk before it replaces the old one, and the rename after."""
    path = tmp_path / "mission.yaml"
    synced: list[tuple[str, str]] = []
    real_fsync = os.fsync

    def fsync(fd: int) -> None:
        kind = "directory" if stat.S_ISDIR(os.fstat(fd).st_mode) else "file"
        synced.append((kind, path.read_text(encoding="utf-8") if path.exists() else ""))
        real_fsync(fd)

    monkeypatch.setattr(durable.os, "fsync", fsync)
    save_mission(path, rich.state.content(), 3)
    saved = path.read_text(encoding="utf-8")
    assert synced == [("file", ""), ("directory", saved)]


def test_save_under_a_name_too_long_for_the_file_system(rich: Any, tmp_path: Path) -> None:
    target = tmp_path / ("x" * 300)
    with pytest.raises(MissionFileError, match="File name too long") as caught:
        save_mission(target, rich.state.content(), 1)
    assert "\n" not in str(caught.value)
    assert list(tmp_path.iterdir()) == []


def test_save_into_a_missing_folder(rich: Any, tmp_path: Path) -> None:
    target = tmp_path / "nowhere" / "m.yaml"
    with pytest.raises(MissionFileError) as caught:
        save_mission(target, rich.state.content(), 1)
    assert str(target) in str(caught.value)
    assert not target.exists()


# -- malformed files -----------------------------------------------------------------


@pytest.fixture
def document(rich: Any) -> dict[str, Any]:
    return copy.deepcopy(mission_to_dict(rich.state.content(), rich.revision))


def _skill(doc: dict[str, Any], agent: str, index: int) -> dict[str, Any]:
    result: dict[str, Any] = doc["tasks"][agent][index]
    return result


def _mutations() -> list[tuple[str, Any, str]]:
    def setter(key: str, value: Any) -> Any:
        return lambda d: d.__setitem__(key, value)

    def skill_set(agent: str, index: int, key: str, value: Any) -> Any:
        return lambda d: _skill(d, agent, index).__setitem__(key, value)

    def param_set(agent: str, index: int, name: str, value: Any) -> Any:
        return lambda d: _skill(d, agent, index)["params"].__setitem__(name, value)

    return [
        ("version-2", setter("rosmc_mission", 2), "unsupported mission file version 2"),
        ("version-text", setter("rosmc_mission", "1"), "rosmc_mission"),
        ("version-bool", setter("rosmc_mission", True), "rosmc_mission"),
        ("no-version", lambda d: d.pop("rosmc_mission"), "missing rosmc_mission"),
        ("no-tasks", lambda d: d.pop("tasks"), "missing tasks"),
        ("unknown-top-key", setter("owner", "me"), "unknown keys owner"),
        ("other-library", setter("library", "mars"), "written for library 'mars'"),
        ("revision-text", setter("revision", "3"), "revision"),
        ("revision-negative", setter("revision", -1), "revision"),
        ("revision-bool", setter("revision", True), "revision"),
        ("tasks-list", setter("tasks", []), "tasks: must be a mapping"),
        ("task-mapping", lambda d: d["tasks"].__setitem__("alpha", {}), "tasks.alpha"),
        ("skill-not-mapping", lambda d: d["tasks"]["bravo"].append("x"), "tasks.bravo[2]"),
        ("skill-unknown-key", skill_set("alpha", 0, "colour", 1), "unknown keys colour"),
        ("skill-no-params", lambda d: _skill(d, "alpha", 0).pop("params"), "missing params"),
        ("params-list", skill_set("alpha", 0, "params", []), "params: must be a mapping"),
        ("id-number", skill_set("alpha", 0, "id", 5), "tasks.alpha[0].id"),
        ("id-empty", skill_set("alpha", 0, "id", " "), "tasks.alpha[0].id"),
        ("label-empty", skill_set("alpha", 0, "label", ""), "label"),
        ("status-unknown", skill_set("alpha", 0, "status", "DONE"), "status: must be one of"),
        ("status-number", skill_set("alpha", 0, "status", 5), "status"),
        ("transfer-unknown", skill_set("alpha", 0, "transfer", "SENDING"), "transfer"),
        ("resolution-bad", skill_set("alpha", 1, "resolution", "IGNORED"), "resolution"),
        ("attempt-zero", skill_set("alpha", 0, "attempt", 0), "attempt"),
        ("attempt-float", skill_set("alpha", 0, "attempt", 1.5), "attempt"),
        ("timeout-negative", skill_set("alpha", 0, "timeout", -1), "timeout"),
        ("timeout-nan", skill_set("alpha", 0, "timeout", float("nan")), "timeout"),
        ("started-text", skill_set("alpha", 0, "started", "noon"), "started"),
        ("max-retries-bool", skill_set("alpha", 0, "max_retries", True), "max_retries"),
        ("status-text-number", skill_set("alpha", 0, "status_text", 3), "status_text"),
        ("bindings-list", skill_set("alpha", 0, "bindings", ["goal"]), "bindings"),
        ("binding-number", skill_set("alpha", 0, "bindings", {"target": 3}), "bindings.target"),
        # duplicate ids
        ("dup-skill-id", skill_set("alpha", 1, "id", "alpha-1"), "'alpha-1' appears twice"),
        ("dup-across-agents", skill_set("bravo", 0, "id", "alpha-1"), "appears twice"),
        (
            "dup-barrier-id",
            lambda d: d["barriers"].append(dict(d["barriers"][0])),
            "appears twice",
        ),
        (
            "barrier-id-is-skill-id",
            lambda d: d["barriers"][0].__setitem__("id", "alpha-1"),
            "appears twice",
        ),
        (
            "dup-marker",
            lambda d: d["markers"].append(dict(d["markers"][0])),
            "'goal' appears twice",
        ),
        # barriers
        (
            "dangling-barrier",
            lambda d: d["barriers"][0]["skills"].__setitem__(0, "ghost"),
            "unknown skill 'ghost'",
        ),
        ("barrier-one-member", lambda d: d["barriers"][0]["skills"].pop(), "at least two"),
        (
            "barrier-same-agent",
            lambda d: d["barriers"][0].__setitem__("skills", ["alpha-1", "alpha-2"]),
            "distinct agents",
        ),
        ("barriers-mapping", setter("barriers", {}), "barriers: must be a list"),
        (
            "barrier-unknown-key",
            lambda d: d["barriers"][0].__setitem__("name", "b"),
            "unknown keys name",
        ),
        (
            "barrier-member-twice",
            lambda d: d["barriers"].append(
                {"id": "b2", "skills": list(d["barriers"][0]["skills"])}
            ),
            "already in another barrier",
        ),
        # agents, skills, parameters
        ("unknown-agent", lambda d: d["tasks"].__setitem__("zulu", []), "tasks.zulu"),
        ("static-agent", lambda d: d["tasks"].__setitem__("base", []), "tasks.base"),
        ("unknown-skill", skill_set("alpha", 0, "skill", "fly"), "no skill 'fly'"),
        ("unknown-param", param_set("alpha", 0, "altitude", 3), "no parameter 'altitude'"),
        ("param-out-of-bounds", param_set("alpha", 0, "speed", 99.0), "at most 2"),
        ("param-wrong-type", param_set("alpha", 1, "passes", "three"), "whole number"),
        ("param-not-a-choice", param_set("alpha", 1, "mode", "turbo"), "one of"),
        ("param-nan", param_set("alpha", 0, "speed", float("nan")), "finite"),
        ("param-missing", lambda d: _skill(d, "alpha", 0)["params"].pop("speed"), "missing speed"),
        # markers
        ("binding-undefined-marker", lambda d: d["markers"].pop(0), "'goal'"),
        (
            "binding-wrong-marker-type",
            skill_set("alpha", 0, "bindings", {"target": "field"}),
            "area marker",
        ),
        ("marker-type-bad", lambda d: d["markers"][0].__setitem__("type", "LINE"), "type"),
        ("marker-pose-text", lambda d: d["markers"][0].__setitem__("pose", "here"), "pose"),
        ("marker-area-two-vertices", lambda d: d["markers"][2]["vertices"].pop(), "3 vertices"),
        (
            "marker-vertices-number",
            lambda d: d["markers"][2].__setitem__("vertices", 5),
            "vertices",
        ),
        ("marker-name-number", lambda d: d["markers"][0].__setitem__("name", 5), "name"),
        ("markers-mapping", setter("markers", {"goal": {}}), "markers: must be a list"),
        # sections
        (
            "synced-after-blueprint",
            lambda d: d["tasks"]["alpha"].insert(0, d["tasks"]["alpha"].pop()),
            "follows a blueprint skill",
        ),
        (
            "started-after-unsettled",
            lambda d: d["tasks"]["alpha"].insert(0, d["tasks"]["alpha"].pop(2)),
            "tasks.alpha[1]",
        ),
        (
            "removing-running",
            lambda d: _skill(d, "alpha", 4).__setitem__("status", "RUNNING"),
            "removing",
        ),
        ("uploading-synced", skill_set("alpha", 0, "transfer", "UPLOADING"), "transfer"),
        ("resolution-on-success", skill_set("alpha", 0, "resolution", "SKIPPED"), "resolution"),
        # what add and edit refuse, a file cannot bring in (core/validation.py)
        ("label-1-mib", skill_set("alpha", 0, "label", "x" * 2**20), "at most 120"),
        ("label-line-break", skill_set("alpha", 0, "label", "two\nlines"), "label"),
        ("label-escape-code", skill_set("alpha", 0, "label", "\x1b[31mred"), "label"),
        ("id-line-break", skill_set("alpha", 0, "id", "a\nb"), "a skill id must be"),
        ("id-escape-code", skill_set("alpha", 0, "id", "\x1b]0;owned\x07"), "a skill id"),
        ("id-too-long", skill_set("alpha", 0, "id", "a" * 65), "a skill id"),
        ("retries-a-billion", skill_set("alpha", 0, "max_retries", 10**9), "from 0 to 100"),
        ("attempt-huge", skill_set("alpha", 0, "attempt", 10**9), "an attempt"),
        ("timeout-infinite", skill_set("alpha", 0, "timeout", float("inf")), "timeout"),
        # integers too large for a float: a sentence, not an OverflowError
        ("timeout-too-large", skill_set("alpha", 0, "timeout", 10**400), "timeout: must"),
        ("started-too-large", skill_set("alpha", 0, "started", 10**400), "started: must"),
        ("param-too-large", param_set("alpha", 0, "speed", 10**400), "finite number"),
        ("status-text-lines", skill_set("alpha", 0, "status_text", "a\nb"), "status text"),
        ("status-text-long", skill_set("alpha", 0, "status_text", "s" * 501), "status text"),
        (
            "marker-name-escape",
            lambda d: d["markers"][1].__setitem__("name", "\x1b[2Jgone"),
            "marker name",
        ),
        ("barrier-id-space", lambda d: d["barriers"][0].__setitem__("id", "b 1"), "barrier id"),
        # deadlock
        (
            "deadlocking-barriers",
            lambda d: (
                d["tasks"]["charlie"].append({"id": "cx", "skill": "noop", "params": {}})
                or d["barriers"].append({"id": "b-x", "skills": ["bravo-7", "cx"]})
            ),
            "deadlock",
        ),
    ]


MUTATIONS = _mutations()


@pytest.mark.parametrize(
    ("mutate", "fragment"), [m[1:] for m in MUTATIONS], ids=[m[0] for m in MUTATIONS]
)
def test_malformed_file_is_refused(
    document: dict[str, Any], library: Any, mutate: Any, fragment: str, tmp_path: Path,
    new_mission_factory: Any, snap: Any,
) -> None:  # fmt: skip
    parse_mission(yaml.safe_dump(document), library, "good.yaml")  # the base document is valid
    mission = new_mission_factory()
    mission.add_skill("alpha", "noop")
    mutate(document)
    path = tmp_path / "bad mission.yaml"
    path.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    before = snap(mission)
    with pytest.raises(MissionFileError) as caught:
        mission.load(*load_mission(path, library)[:1], str(path))
    message = str(caught.value)
    assert message.startswith(f"{path}: "), message
    assert fragment in message, message
    assert "\n" not in message and "\x1b" not in message
    assert len(message) < 400, "an error quotes a short, escaped excerpt of the input"
    assert snap(mission) == before


def test_the_ids_the_mutations_rely_on(document: dict[str, Any]) -> None:
    # Guard for the table above: with barrier {bravo-8, charlie-9}, a barrier
    # {bravo-7, cx} with cx after charlie-9 closes a cycle.
    tasks = {agent: [s["id"] for s in task] for agent, task in document["tasks"].items()}
    assert tasks["alpha"][:2] == ["alpha-1", "alpha-2"]
    assert tasks["bravo"] == ["bravo-7", "bravo-8"]
    assert tasks["charlie"] == ["charlie-11", "charlie-9"]
    assert document["barriers"][0]["skills"] == ["bravo-8", "charlie-9"]
    assert document["tasks"]["alpha"][4]["transfer"] == "REMOVING"


@pytest.mark.parametrize(
    "text",
    [
        "tasks: [unclosed\n",
        "a: 1\n  b: 2\n",
        "key: 'open\n",
        "- a\nb: 1\n",
        "\t- tab\n",
    ],
)
def test_invalid_yaml_gives_one_line(library: Any, text: str) -> None:
    with pytest.raises(MissionFileError) as caught:
        parse_mission(text, library, "broken.yaml")
    message = str(caught.value)
    assert message.startswith("broken.yaml: ") and "\n" not in message


def test_a_key_given_twice_is_refused_not_overwritten(document: Any, library: Any) -> None:
    text = yaml.safe_dump(document, sort_keys=False)
    twice = text.replace("tasks:\n", "tasks:\n  alpha: []\n", 1)
    with pytest.raises(MissionFileError, match=r"duplicate key 'alpha' at line \d+"):
        parse_mission(twice, library, "twice.yaml")


@pytest.mark.parametrize("text", ["", "just text", "[1, 2]", "42", "null"])
def test_non_mapping_document(library: Any, text: str) -> None:
    with pytest.raises(MissionFileError, match="must be a mapping"):
        parse_mission(text, library, "x.yaml")


@pytest.mark.parametrize(
    "tag",
    [
        "!!python/object/apply:os.system",
        "!!python/object/new:os.system",
        "!!python/name:os.system",
    ],
)
def test_python_object_tag_is_refused_not_executed(
    library: Any, tmp_path: Path, tag: str, mission: Any, snap: Any
) -> None:
    touched = tmp_path / "pwned"
    path = tmp_path / "evil.yaml"
    path.write_text(
        f'rosmc_mission: 1\nlibrary: unit_team\nrevision: 0\ntasks: {tag} ["touch {touched}"]\n',
        encoding="utf-8",
    )
    before = snap(mission)
    with pytest.raises(MissionFileError) as caught:
        load_mission(path, library)
    assert str(path) in str(caught.value) and "\n" not in str(caught.value)
    assert not touched.exists()
    assert snap(mission) == before


def test_python_tag_deep_inside_is_refused(library: Any, tmp_path: Path) -> None:
    touched = tmp_path / "pwned"
    text = (
        "rosmc_mission: 1\nlibrary: unit_team\nrevision: 0\ntasks:\n  alpha:\n"
        "  - id: a\n    skill: wait\n    params:\n"
        f'      note: !!python/object/apply:os.system ["touch {touched}"]\n'
    )
    with pytest.raises(MissionFileError, match="tag"):
        parse_mission(text, library, "evil.yaml")
    assert not touched.exists()


def test_unreadable_files(library: Any, tmp_path: Path) -> None:
    with pytest.raises(MissionFileError, match="cannot read"):
        load_mission(tmp_path / "missing.yaml", library)
    with pytest.raises(MissionFileError, match="cannot read"):
        load_mission(tmp_path, library)
    latin = tmp_path / "latin1.yaml"
    latin.write_bytes(b"rosmc_mission: 1\nlibrary: caf\xe9\n")
    with pytest.raises(MissionFileError) as caught:
        load_mission(latin, library)
    assert str(latin) in str(caught.value)


def test_mission_from_dict_does_not_modify_its_input(
    document: dict[str, Any], library: Any
) -> None:
    before = copy.deepcopy(document)
    mission_from_dict(document, library, "x")
    assert document == before


def test_content_holds_only_what_the_file_says(library: Any) -> None:
    content, _ = parse_mission(
        "rosmc_mission: 1\nlibrary: unit_team\nrevision: 0\ntasks: {}\n", library, "x"
    )
    assert content == MissionContent.empty(library)


@pytest.mark.parametrize("depth", [150, 100_000])
def test_deeply_nested_documents_are_refused_before_parsing(library: Library, depth: int) -> None:
    """libyaml crashes the process on deep enough nesting; such a document never reaches it."""
    for text in ("x: " + "[" * depth + "]" * depth, "x: " + "{a: " * depth + "}" * depth):
        with pytest.raises(MissionFileError, match="nested more than"):
            parse_mission(text, library, "deep.yaml")


def test_a_parameter_value_nested_too_deeply_is_refused(mission: Mission) -> None:
    deep: object = []
    for _ in range(40):
        deep = [deep]
    with pytest.raises(InvalidRequest, match="nested more than"):
        mission.add_skill("alpha", "wait", {"options": {"deep": deep}})


def test_each_message_names_the_file_once(document: dict[str, Any], library: Any) -> None:
    for mutate in (
        lambda d: _skill(d, "alpha", 0)["params"].pop("speed"),
        lambda d: _skill(d, "alpha", 0).__setitem__("skill", "fly"),
        lambda d: d["markers"][0].__setitem__("pose", "here"),
    ):
        broken = copy.deepcopy(document)
        mutate(broken)
        with pytest.raises(MissionFileError) as caught:
            parse_mission(yaml.safe_dump(broken), library, "once.yaml")
        assert str(caught.value).count("once.yaml") == 1, str(caught.value)


def test_ordinary_yaml_aliases_load(library: Any) -> None:
    # yaml.safe_dump writes shared values as anchors and aliases; such files load.
    text = (
        "rosmc_mission: 1\nlibrary: unit_team\nrevision: 0\ntasks:\n  alpha:\n"
        "  - id: a\n    skill: scan\n    params: &params\n"
        "      area: [{x: 0, y: 0}, {x: 1, y: 0}, {x: 0, y: 1}]\n"
        "      point: {x: 1.0}\n      mode: slow\n      passes: 2\n"
        "  - {id: b, skill: scan, params: *params}\n"
    )
    content, _ = parse_mission(text, library, "alias.yaml")
    first, second = content.tasks["alpha"]
    assert first.params["area"] == second.params["area"]


def test_an_alias_bomb_is_refused_at_once(library: Any) -> None:
    # "Billion laughs": 8 levels of 10 aliases each would expand to 10**9 values.
    lines = ["        k0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"        k{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 9)]
    text = (
        "rosmc_mission: 1\nlibrary: unit_team\nrevision: 0\ntasks:\n  alpha:\n"
        "  - id: s\n    skill: wait\n    params:\n      options:\n" + "\n".join(lines) + "\n"
    )
    # Refused by counting the aliases: expanding them would never end (pytest's timeout).
    with pytest.raises(MissionFileError, match="aliases expand it") as caught:
        parse_mission(text, library, "bomb.yaml")
    assert str(caught.value).startswith("bomb.yaml: ")
