"""Every rosdep key in package.xml resolves, so `rosdep install` can set a workspace up.

rosdistro cannot be reached from here: tools/rosdep_offline.sh gives rosdep Debian's ROS rules,
the project's rosdep/ files (as rosdep/sources.sh lists them, the line a user adds to
/etc/ros/rosdep/sources.list.d) and the rosdistro entries package.xml uses.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from tests.integration.conftest import Run

REPO_ROOT = Path(__file__).resolve().parents[2]
OFFLINE = REPO_ROOT / "tools" / "rosdep_offline.sh"

# What the keys that are not plain ROS packages install on Debian.
EXPECTED = {
    "python3-mcap-pip": ("pip", ["mcap"]),
    "python3-mcap-ros1-support-pip": ("pip", ["mcap-ros1-support"]),
    "python3-pybullet-pip": ("pip", ["pybullet"]),
    "python3-zstandard": ("apt", ["python3-zstandard"]),
    "python3-yaml": ("apt", ["python3-yaml"]),
    "rqt_gui": ("apt", []),  # Debian has no rqt; the command GUI runs standalone there
    "rospy": ("apt", ["python3-rospy"]),
}


def resolved(output: str) -> dict[str, tuple[str, list[str]]]:
    """``rosdep resolve`` output as key -> (installer, packages)."""
    found: dict[str, tuple[str, list[str]]] = {}
    for block in output.split("#ROSDEP[")[1:]:
        key, _, rest = block.partition("]\n")
        lines = rest.splitlines()
        found[key] = (lines[0].lstrip("#"), " ".join(lines[1:]).split())
    return found


def test_every_key_of_package_xml_resolves(tmp_path: Path, run: Run) -> None:
    db = tmp_path / "rosdep"
    env = dict(os.environ)
    keys = run([OFFLINE, db, "rosdep", "keys", "--from-paths", REPO_ROOT, "--ignore-src"], env)
    names = sorted(set(keys.stdout.split()))
    assert set(EXPECTED) <= set(names)
    answers = resolved(run([OFFLINE, db, "rosdep", "resolve", *names], env).stdout)
    assert sorted(answers) == names
    for key, expected in EXPECTED.items():
        assert answers[key] == expected, key


def test_rosdep_install_accepts_the_workspace(tmp_path: Path, run: Run) -> None:
    # docs/workspace.md: `rosdep install --from-paths src --ignore-src -y` in the workspace;
    # simulated, so that it prints what it would install and changes nothing.
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "rosmc").symlink_to(REPO_ROOT, target_is_directory=True)
    argv = [OFFLINE, tmp_path / "rosdep", "rosdep", "install", "--simulate"]
    argv += ["--from-paths", "src", "--ignore-src", "-y"]
    result = run(argv, dict(os.environ), cwd=tmp_path)
    assert "ERROR" not in result.stdout + result.stderr, result.stderr


def requirement_names() -> set[str]:
    """The PyPI packages requirements.txt installs into .venv (names as pip spells them)."""
    lines = (REPO_ROOT / "requirements.txt").read_text().splitlines()
    return {line.split("==")[0].strip().lower() for line in lines if "==" in line}


def test_make_setup_installs_what_every_key_of_package_xml_resolves_to(
    tmp_path: Path, run: Run
) -> None:
    db = tmp_path / "rosdep"
    env = dict(os.environ)
    keys = run([OFFLINE, db, "rosdep", "keys", "--from-paths", REPO_ROOT, "--ignore-src"], env)
    names = sorted(set(keys.stdout.split()))
    answers = resolved(run([OFFLINE, db, "rosdep", "resolve", *names], env).stdout)
    apt = set(run(["make", "-s", "-C", REPO_ROOT, "apt-packages"], env).stdout.split())
    pip = requirement_names()
    missing = sorted(
        f"{key}: {package} ({installer})"
        for key, (installer, packages) in answers.items()
        for package in packages
        if package.lower() not in (apt if installer == "apt" else pip)
    )
    assert missing == [], f"add them to the Makefile's APT_PACKAGES or requirements.txt: {missing}"


def test_rosdep_check_is_clean_after_make_setup(tmp_path: Path, run: Run) -> None:
    # After `make setup`, in a shell with env.sh sourced (rosdep asks the `pip3` first on
    # PATH, the venv's, about the -pip keys), as docs/workspace.md says.
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "rosmc").symlink_to(REPO_ROOT, target_is_directory=True)
    argv = [OFFLINE, tmp_path / "rosdep", "rosdep", "check", "--from-paths", "src"]
    result = run([*argv, "--ignore-src"], dict(os.environ), cwd=tmp_path)
    assert "All system dependencies have been satisfied" in result.stdout, result.stdout


def test_the_docs_name_every_pip_key() -> None:
    package_xml = (REPO_ROOT / "package.xml").read_text()
    keys = sorted(set(re.findall(r">(python3-[\w-]+-pip)<", package_xml)))
    assert len(keys) >= 4
    workspace = (REPO_ROOT / "docs" / "workspace.md").read_text()
    assert [key for key in keys if f"`{key}`" not in workspace] == []
