"""``extends``: a library adds robots to another, and may not change what the base says."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
import yaml

from rosmc_server.core import LibraryError, ParamType, load_library
from rosmc_server.core.skills.package_paths import PackagePath, package_reference

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


# -- extends by package ------------------------------------------------------------------

MARS_IN_PACKAGE = "rosmc_server/config/mars_team.yaml"


def package(folder: Path, name: str) -> Path:
    """A ROS package folder named ``name`` (its package.xml) at ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(
        f'<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n</package>\n'
    )
    return folder


def lab_library(folder: Path, extends: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    models = {"heli": HELI}
    agents = {"heli1": {"kind": "dynamic", "model": "heli"}}
    data = {"rosmc_library": 1, "name": "lab", "extends": extends, "models": models}
    return write(folder, "lab.yaml", {**data, "agents": agents})


@pytest.mark.parametrize(
    "extends", [f"package://rosmc/{MARS_IN_PACKAGE}", f"$(find rosmc)/{MARS_IN_PACKAGE}"]
)
def test_a_lab_package_extends_the_team_by_package_in_a_source_workspace(
    tmp_path: Path, extends: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A workspace's src/ with the lab's package; rosmc is the checkout (a devel space).
    lab = package(tmp_path / "src" / "lab_robots", "lab_robots")
    path = lab_library(lab / "config", extends)
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"{tmp_path / 'src'}:{REPO}")
    plus = load_library(path)  # the environment's ROS_PACKAGE_PATH, as roslaunch's
    assert [a.name for a in plus.agents] == [*(a.name for a in load_library(MARS).agents), "heli1"]


def test_extends_by_package_finds_colcons_isolated_install_layout(tmp_path: Path) -> None:
    # colcon build --install-base install: install/<pkg>/share/<pkg> for each package.
    share = package(tmp_path / "install" / "rosmc" / "share" / "rosmc", "rosmc")
    (share / "rosmc_server" / "config").mkdir(parents=True)
    (share / MARS_IN_PACKAGE).write_text(MARS.read_text())
    lab = package(tmp_path / "install" / "lab_robots" / "share" / "lab_robots", "lab_robots")
    path = lab_library(lab / "config", f"package://rosmc/{MARS_IN_PACKAGE}")
    roots = f"{tmp_path / 'install' / 'lab_robots' / 'share'}:{tmp_path / 'install/rosmc/share'}"
    plus = load_library(path, find_package=PackagePath.parse(roots))
    assert "heli1" in {a.name for a in plus.agents} and "drone" in {a.name for a in plus.agents}


def test_a_package_folder_named_otherwise_is_found_by_its_package_xml(tmp_path: Path) -> None:
    renamed = package(tmp_path / "src" / "checkouts" / "rosmc-2.1", "rosmc")
    (renamed / "rosmc_server" / "config").mkdir(parents=True)
    (renamed / MARS_IN_PACKAGE).write_text(MARS.read_text())
    finder = PackagePath.parse(str(tmp_path / "src"))
    assert finder("rosmc") == renamed
    assert finder("nothing_here") is None


def test_an_unknown_package_is_named_in_one_sentence(tmp_path: Path) -> None:
    path = lab_library(tmp_path, f"package://rosmc_lab/{MARS_IN_PACKAGE}")
    with pytest.raises(LibraryError) as caught:
        load_library(path, find_package=PackagePath.parse(str(REPO)))
    assert str(caught.value) == (
        f"{path}: extends: package://rosmc_lab/{MARS_IN_PACKAGE}: no ROS package 'rosmc_lab' "
        "on ROS_PACKAGE_PATH (source the setup.bash of the workspace that holds it)"
    )


def test_package_references_are_told_from_paths() -> None:
    assert package_reference("package://rosmc/a/b.yaml") == ("rosmc", "a/b.yaml")
    assert package_reference("$(find lab_robots)/config/lab.yaml") == (
        "lab_robots",
        "config/lab.yaml",
    )
    assert package_reference("mars_team.yaml") is None
    assert package_reference("/abs/mars_team.yaml") is None
