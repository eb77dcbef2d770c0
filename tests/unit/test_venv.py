"""rosmc_server.venv: where entry scripts look for the project's PyPI packages."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from rosmc_server import venv


def test_rosmc_venv_comes_first_then_the_checkouts_venv(tmp_path: Path) -> None:
    found = venv.candidate_venvs({"ROSMC_VENV": str(tmp_path / "mine")})
    assert found[0] == tmp_path / "mine"
    checkout = Path(venv.__file__).resolve().parents[1]
    assert checkout / ".venv" in found[1:]


def test_site_packages_goes_before_debians_packages(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    packages = venv.site_packages(tmp_path)
    packages.mkdir(parents=True)
    path = ["/usr/lib/python3.11", "/usr/lib/python3/dist-packages", "/opt/ros/lib"]
    monkeypatch.setattr(sys, "path", path)
    monkeypatch.setattr(sys, "prefix", sys.base_prefix)  # as /usr/bin/python3 runs a relay

    assert venv.use_project_venv({"ROSMC_VENV": str(tmp_path)}) == tmp_path
    assert path[1] == str(packages)
    assert venv.use_project_venv({"ROSMC_VENV": str(tmp_path)}) == tmp_path
    assert path.count(str(packages)) == 1, "a second call adds nothing"


def test_nothing_changes_inside_a_venv_or_without_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = ["/usr/lib/python3/dist-packages"]
    monkeypatch.setattr(sys, "path", path)
    monkeypatch.setattr(sys, "prefix", "/somewhere/else")
    venv.site_packages(tmp_path).mkdir(parents=True)
    assert venv.use_project_venv({"ROSMC_VENV": str(tmp_path)}) is None

    monkeypatch.setattr(sys, "prefix", sys.base_prefix)
    monkeypatch.setattr(venv, "_package_path", lambda: [str(tmp_path / "nowhere" / "pkg")])
    assert venv.use_project_venv({}) is None
    assert path == ["/usr/lib/python3/dist-packages"]
