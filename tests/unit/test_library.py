"""Skill library loading: the shipped file loads, every malformed file is refused clearly."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
import yaml

from rosmc_server.core import (
    AgentKind,
    LibraryError,
    MarkerType,
    NotFound,
    ParamType,
    Pose,
    RuleViolation,
    load_library,
)
from rosmc_server.core.skills.library import library_from_dict
from rosmc_server.core.world.site import SiteCheck


def write(tmp_path: Path, data: Any, name: str = "team.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def refused(path: Path, *fragments: str) -> str:
    """Load ``path``; it must fail with one line naming the file and each fragment."""
    with pytest.raises(LibraryError) as caught:
        load_library(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: "), message
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    return message


# -- the shipped library ---------------------------------------------------------


def test_shipped_library_loads(shipped_library: Any) -> None:
    assert shipped_library.name == "mars_sample_return"
    assert shipped_library.dynamic_agents == ("drone", "science_rover", "manipulator_rover")
    assert shipped_library.agent("lander").kind is AgentKind.STATIC
    fly_over = shipped_library.skill("drone", "fly_over")
    assert fly_over.parameter("area").marker_type is MarkerType.AREA
    assert fly_over.parameter("altitude").minimum == 2.0
    assert fly_over.estimated_duration == 90
    mode = shipped_library.skill("science_rover", "identify_stones").parameter("mode")
    assert mode.choices == ("quick", "standard", "detailed")
    target = shipped_library.skill("manipulator_rover", "navigate_to").parameter("target")
    # Beside the lander, not on it: a rover's target must be ground it can stand on.
    assert target.type is ParamType.POSE and target.default == Pose(5.0, 0.0)
    assert target.check_target is SiteCheck.REACHABLE_GROUND
    assert fly_over.parameter("area").check_target is SiteCheck.ON_SITE


def test_shipped_library_every_dynamic_agent_has_skills(shipped_library: Any) -> None:
    for agent in shipped_library.dynamic_agents:
        assert shipped_library.skills_of(agent)


def test_test_library_parses(library: Any) -> None:
    assert library.dynamic_agents == ("alpha", "bravo", "charlie")
    assert library.skill("alpha", "noop").parameters == ()
    assert library.skill("alpha", "wait").defaults() == {
        "seconds": 0,
        "verbose": False,
        "note": "",
        "options": {},
    }


def test_library_lookups_refuse_unknown_names(library: Any) -> None:
    with pytest.raises(NotFound, match="no agent 'zulu'"):
        library.agent("zulu")
    with pytest.raises(NotFound, match="no skill 'fly'"):
        library.skill("alpha", "fly")
    with pytest.raises(RuleViolation, match="static agent"):
        library.skill("base", "move")
    with pytest.raises(NotFound, match="no parameter 'x'"):
        library.skill("alpha", "move").parameter("x")


# -- malformed files: one case per class of mistake ------------------------------

MOVE = "models.walker.skills.move"
SPEED = f"{MOVE}.parameters.speed"
SCAN = "models.walker.skills.scan"


def _set(data: dict[str, Any], dotted: str, value: Any) -> None:
    keys = dotted.split(".")
    for key in keys[:-1]:
        data = data[key]
    data[keys[-1]] = value


def _delete(data: dict[str, Any], dotted: str) -> None:
    keys = dotted.split(".")
    for key in keys[:-1]:
        data = data[key]
    del data[keys[-1]]


# (id, mutation, fragments the message must contain)
BROKEN: list[tuple[str, Any, tuple[str, ...]]] = [
    # version
    ("version-2", lambda d: _set(d, "rosmc_library", 2), ("rosmc_library", "version 2")),
    ("version-text", lambda d: _set(d, "rosmc_library", "one"), ("rosmc_library", "version")),
    ("version-bool", lambda d: _set(d, "rosmc_library", True), ("rosmc_library", "version")),
    ("version-missing", lambda d: _delete(d, "rosmc_library"), ("missing", "rosmc_library")),
    # missing keys
    ("no-models", lambda d: _delete(d, "models"), ("missing", "models")),
    ("no-agents", lambda d: _delete(d, "agents"), ("missing", "agents")),
    ("no-name", lambda d: _delete(d, "name"), ("missing", "name")),
    ("agent-no-kind", lambda d: _delete(d, "agents.alpha.kind"), ("agents.alpha", "kind")),
    ("agent-no-model", lambda d: _delete(d, "agents.alpha.model"), ("agents.alpha", "model")),
    ("model-no-skills", lambda d: _delete(d, "models.walker.skills"), ("models.walker", "skills")),
    ("param-no-type", lambda d: _delete(d, f"{SPEED}.type"), (SPEED, "missing", "type")),
    ("param-no-default", lambda d: _delete(d, f"{SPEED}.default"), (SPEED, "default")),
    ("no-agents-at-all", lambda d: _set(d, "agents", {}), ("agents", "no agents")),
    # unknown keys
    ("unknown-top", lambda d: _set(d, "colour", "red"), ("unknown", "colour")),
    ("unknown-agent-key", lambda d: _set(d, "agents.alpha.speed", 3), ("agents.alpha", "speed")),
    ("unknown-model-key", lambda d: _set(d, "models.walker.size", 3), ("models.walker", "size")),
    ("unknown-skill-key", lambda d: _set(d, f"{MOVE}.cost", 3), (MOVE, "unknown", "cost")),
    ("unknown-param-key", lambda d: _set(d, f"{SPEED}.step", 1), (SPEED, "unknown", "step")),
    # wrong types
    ("name-number", lambda d: _set(d, "name", 5), ("name", "text")),
    ("models-list", lambda d: _set(d, "models", []), ("models", "mapping")),
    ("agents-list", lambda d: _set(d, "agents", ["alpha"]), ("agents", "mapping")),
    ("kind-bad", lambda d: _set(d, "agents.alpha.kind", "flying"), ("agents.alpha.kind",)),
    ("type-bad", lambda d: _set(d, f"{SPEED}.type", "double"), (f"{SPEED}.type", "double")),
    ("min-text", lambda d: _set(d, f"{SPEED}.min", "low"), (f"{SPEED}.min", "number")),
    ("min-nan", lambda d: _set(d, f"{SPEED}.min", float("nan")), (f"{SPEED}.min",)),
    ("max-inf", lambda d: _set(d, f"{SPEED}.max", float("inf")), (f"{SPEED}.max",)),
    ("duration-text", lambda d: _set(d, f"{MOVE}.duration", "5s"), (f"{MOVE}.duration",)),
    ("duration-negative", lambda d: _set(d, f"{MOVE}.duration", -1), (f"{MOVE}.duration",)),
    ("duration-inf", lambda d: _set(d, f"{MOVE}.duration", float("inf")), (f"{MOVE}.duration",)),
    ("default-wrong-type", lambda d: _set(d, f"{SPEED}.default", "fast"), (SPEED, "number")),
    ("int-default-float", lambda d: _set(d, f"{SCAN}.parameters.passes.default", 1.5), ("passes",)),
    (
        "bool-default-int",
        lambda d: _set(d, "models.walker.skills.wait.parameters.verbose.default", 1),
        ("verbose",),
    ),
    (
        "choices-not-list",
        lambda d: _set(d, f"{SCAN}.parameters.mode.choices", "fast"),
        ("choices", "list"),
    ),
    (
        "choice-wrong-type",
        lambda d: _set(d, f"{SCAN}.parameters.mode.choices", ["fast", 3]),
        ("choices",),
    ),
    (
        "params-list",
        lambda d: _set(d, f"{MOVE}.parameters", ["speed"]),
        (f"{MOVE}.parameters", "mapping"),
    ),
    (
        "description-number",
        lambda d: _set(d, "agents.alpha.description", 7),
        ("agents.alpha.description",),
    ),
    ("bounds-on-string", lambda d: _set(d, f"{SCAN}.parameters.mode.min", 1), ("min and max",)),
    # min > max, defaults outside bounds or choices
    ("min-above-max", lambda d: _set(d, f"{SPEED}.min", 3.0), (SPEED, "min 3", "max 2")),
    ("default-below-min", lambda d: _set(d, f"{SPEED}.default", 0.0), (SPEED, "at least 0.1")),
    ("default-above-max", lambda d: _set(d, f"{SPEED}.default", 9.0), (SPEED, "at most 2")),
    (
        "default-not-in-choices",
        lambda d: _set(d, f"{SCAN}.parameters.mode.default", "medium"),
        ("mode", "one of", "medium"),
    ),
    # marker type incompatible with the parameter type
    (
        "area-on-pose",
        lambda d: _set(d, f"{MOVE}.parameters.target.marker", "area"),
        ("target.marker", "list"),
    ),
    (
        "pose-on-list",
        lambda d: _set(d, f"{SCAN}.parameters.area.marker", "pose"),
        ("area.marker", "pose"),
    ),
    ("marker-on-float", lambda d: _set(d, f"{SPEED}.marker", "position"), ("speed.marker",)),
    ("marker-unknown", lambda d: _set(d, f"{SPEED}.marker", "circle"), ("speed.marker", "circle")),
    # a dynamic agent whose model does not exist
    (
        "dynamic-unknown-model",
        lambda d: _set(d, "agents.alpha.model", "hover"),
        ("agents.alpha.model", "hover"),
    ),
]


@pytest.mark.parametrize(
    ("mutate", "fragments"), [c[1:] for c in BROKEN], ids=[c[0] for c in BROKEN]
)
def test_malformed_library_is_refused(
    tmp_path: Path, library_data: dict[str, Any], mutate: Any, fragments: tuple[str, ...]
) -> None:
    mutate(library_data)
    refused(write(tmp_path, library_data), *fragments)


def test_static_agent_may_name_an_unknown_model(
    tmp_path: Path, library_data: dict[str, Any]
) -> None:
    library_data["agents"]["base"]["model"] = "anything"
    library = load_library(write(tmp_path, library_data))
    assert library.skills_of("base") == {}


def test_top_level_must_be_a_mapping(tmp_path: Path) -> None:
    refused(write(tmp_path, ["a", "list"]), "mapping")
    path = tmp_path / "empty.yaml"
    path.write_text("", encoding="utf-8")
    refused(path, "mapping")


def test_invalid_yaml_is_refused_with_the_line(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text("rosmc_library: 1\nname: [unclosed\nmodels: {}\n", encoding="utf-8")
    refused(path, "not valid YAML", "line")


def test_a_key_given_twice_is_refused_with_its_name_and_line(tmp_path: Path) -> None:
    path = tmp_path / "twice.yaml"
    path.write_text(
        "rosmc_library: 1\nname: team\nmodels: {}\nagents: {}\nname: other\n", encoding="utf-8"
    )
    refused(path, "duplicate key 'name'", "line 5")


def test_python_tag_in_library_is_refused_not_run(tmp_path: Path) -> None:
    marker = tmp_path / "touched"
    path = tmp_path / "evil.yaml"
    path.write_text(
        f"rosmc_library: 1\nname: !!python/object/apply:os.system ['touch {marker}']\n",
        encoding="utf-8",
    )
    refused(path, "YAML")
    assert not marker.exists()


def test_missing_file_is_refused(tmp_path: Path) -> None:
    refused(tmp_path / "nowhere.yaml", "cannot read")


def test_directory_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "folder.yaml"
    folder.mkdir()
    refused(folder, "cannot read")


def test_non_utf8_file_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes(b"rosmc_library: 1\nname: caf\xe9\n")
    refused(path)


def test_library_from_dict_names_its_source(library_data: dict[str, Any]) -> None:
    library_data["rosmc_library"] = 7
    with pytest.raises(LibraryError, match=r"^my\.yaml: rosmc_library: unsupported version 7$"):
        library_from_dict(library_data, "my.yaml")


def test_loading_does_not_modify_the_data(library_data: dict[str, Any]) -> None:
    before = copy.deepcopy(library_data)
    library_from_dict(library_data, "x")
    assert library_data == before
