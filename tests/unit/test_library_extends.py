"""``extends``: a library adds robots to another, and may not change what the base says."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from rosmc_server.core import LibraryError, ParamType, load_library

REPO = Path(__file__).resolve().parents[2]
MARS = REPO / "rosmc_server" / "config" / "mars_team.yaml"


def write(folder: Path, name: str, data: Any) -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def extension(**fields: Any) -> dict[str, Any]:
    """An extension of the Mars library (by absolute path) with ``fields`` added."""
    return {"rosmc_library": 1, "name": "mars_plus", "extends": str(MARS), **fields}


def refused(path: Path, text: str) -> None:
    with pytest.raises(LibraryError) as caught:
        load_library(path)
    assert str(caught.value) == text


HELI = {
    "description": "A second aerial robot.",
    "skills": {"hover": {"parameters": {"height": {"type": "float", "default": 2.0}}}},
}


def test_an_extension_adds_robot_kinds_agents_and_skills_to_its_base(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        "plus.yaml",
        extension(
            models={
                "heli": HELI,
                "drone_scout": {"skills": {"beep": {"description": "Beep once."}}},
            },
            agents={"heli1": {"kind": "dynamic", "model": "heli"}},
        ),
    )
    base, plus = load_library(MARS), load_library(path)
    assert plus.name == "mars_plus"
    assert [a.name for a in plus.agents] == [*(a.name for a in base.agents), "heli1"]
    assert plus.skill("heli1", "hover").parameter("height").type is ParamType.FLOAT
    assert set(plus.skills_of("drone")) == {*base.skills_of("drone"), "beep"}
    assert plus.skills_of("science_rover") == base.skills_of("science_rover")
    assert plus.default_policy("drone") == base.default_policy("drone")


def test_extends_is_a_path_from_the_extending_file_and_chains(tmp_path: Path) -> None:
    (tmp_path / "team").mkdir()
    write(tmp_path / "team", "base.yaml", yaml.safe_load(MARS.read_text()))
    middle = {**extension(models={"heli": HELI}), "extends": "team/base.yaml"}
    write(tmp_path, "middle.yaml", middle)
    top = write(
        tmp_path,
        "top.yaml",
        {
            "rosmc_library": 1,
            "name": "top",
            "extends": "middle.yaml",
            "agents": {"heli1": {"kind": "dynamic", "model": "heli"}},
        },
    )
    assert "hover" in load_library(top).skills_of("heli1")


@pytest.mark.parametrize(
    ("fields", "problem"),
    [
        (
            {"agents": {"drone": {"kind": "dynamic", "model": "drone_scout"}}},
            "agents.drone: is an agent of the base library already",
        ),
        (
            {"models": {"drone_scout": {"skills": {"land": {}}}}},
            "models.drone_scout.skills.land: is a skill of the base library already",
        ),
        (
            {"models": {"drone_scout": {"description": "Other.", "skills": {}}}},
            "models.drone_scout: is a model of the base: add skills to it, not description",
        ),
        ({"rosmc_library": 2}, "rosmc_library: differs from its base's (1)"),
        ({"agents": {"x": {"kind": "dynamic", "model": "nope"}}}, "agents.x.model: names no"),
    ],
)
def test_an_extension_may_not_change_its_base(
    tmp_path: Path, fields: dict[str, Any], problem: str
) -> None:
    path = write(tmp_path, "plus.yaml", extension(**fields))
    with pytest.raises(LibraryError) as caught:
        load_library(path)
    assert str(caught.value).startswith(f"{path}: {problem}")


def test_a_loop_of_extends_and_a_missing_base_are_refused(tmp_path: Path) -> None:
    a = write(tmp_path, "a.yaml", {**extension(), "extends": "b.yaml"})
    write(tmp_path, "b.yaml", {**extension(), "extends": "a.yaml"})
    refused(a, f"{tmp_path / 'b.yaml'}: extends: a.yaml extends this library again (a loop)")
    lonely = write(tmp_path, "lonely.yaml", {**extension(), "extends": "gone.yaml"})
    with pytest.raises(LibraryError) as caught:
        load_library(lonely)
    assert str(caught.value).startswith(f"{tmp_path / 'gone.yaml'}: cannot read the library file")


def test_a_mistake_in_the_base_is_named_in_the_base(tmp_path: Path) -> None:
    write(tmp_path, "base.yaml", {"rosmc_library": 1, "name": "b", "models": {}, "agents": {}})
    path = write(tmp_path, "plus.yaml", {**extension(), "extends": "base.yaml"})
    refused(path, f"{tmp_path / 'base.yaml'}: agents: the library declares no agents")
