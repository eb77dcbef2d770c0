"""The Python client as a lab's script sees it: typed, with one error root it can name.

``mypy --strict`` checks a client script outside the checkout against the packages'
annotations (``py.typed``), and ``RosmcError`` is importable from the client package as the
root of every error it raises. No ROS master.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import rosmc_server.core as core
import rosmc_server.ros.client as client

REPO = Path(__file__).resolve().parents[2]

SCRIPT = """\
from rosmc_server.ros.client import MissionClient, RevisionConflict, RosmcError, SkillAdded


def add(client: MissionClient) -> SkillAdded | None:
    try:
        return client.add_skill("drone", "take_off", {"altitude": 8.0})
    except RevisionConflict:
        return None
    except RosmcError as error:
        print(f"refused: {error}")
        return None


def main() -> int:
    with MissionClient(timeout=5.0) as client:
        added = add(client)
        return client.get_mission().revision if added else 1
"""


def test_rosmc_error_is_the_root_of_what_the_client_raises() -> None:
    assert "RosmcError" in client.__all__
    assert client.RosmcError is core.RosmcError
    for name in ("RevisionConflict", "ServerUnavailable"):
        assert issubclass(getattr(client, name), client.RosmcError), name


def test_every_package_is_marked_typed() -> None:
    packages = sorted(init.parent.name for init in REPO.glob("rosmc_*/__init__.py"))
    assert len(packages) == 4
    assert [name for name in packages if not (REPO / name / "py.typed").is_file()] == []


def test_mypy_strict_checks_a_client_script(tmp_path: Path) -> None:
    script = tmp_path / "lab_tool.py"
    script.write_text(SCRIPT)
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--cache-dir", str(tmp_path / "cache"), script],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
