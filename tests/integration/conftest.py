"""Integration tier: every test here is marked ``integration``; build helpers as fixtures."""

from __future__ import annotations

import os
import shlex
import subprocess
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent

# What env.sh, a catkin setup.bash, a venv or colcon put into the environment.
WORKSPACE_VARIABLES = (
    "PYTHONPATH",
    "PYTHONUSERBASE",
    "VIRTUAL_ENV",
    "CMAKE_PREFIX_PATH",
    "PKG_CONFIG_PATH",
    "LD_LIBRARY_PATH",
    "ROS_PACKAGE_PATH",
    "ROS_ETC_DIR",
    "ROS_DISTRO",
    "ROS_VERSION",
    "ROS_PYTHON_VERSION",
    "ROS_MASTER_URI",
    "ROS_IP",
    "ROS_HOSTNAME",
    "ROSLISP_PACKAGE_DIRECTORIES",
    "ROSMC_ROOT",
    "CATKIN_SHELL",
    "_CATKIN_SETUP_DIR",
    "COLCON_PREFIX_PATH",
    "AMENT_PREFIX_PATH",
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test below this folder ``integration``."""
    for item in items:
        if HERE in Path(str(item.path)).resolve().parents:
            item.add_marker(pytest.mark.integration)


def _outside_checkout(entry: str) -> bool:
    path = Path(entry).resolve() if entry else Path()
    return not entry or REPO_ROOT not in (path, *path.parents)


@pytest.fixture
def clean_env(tmp_path: Path) -> dict[str, str]:
    """The environment of a fresh shell: none of env.sh's or a workspace's settings.

    PATH loses the venv, scripts/ and build/ entries; ROS_HOME is private to the test.
    """
    env = {key: value for key, value in os.environ.items() if key not in WORKSPACE_VARIABLES}
    env["PATH"] = ":".join(
        entry for entry in os.environ.get("PATH", "").split(":") if _outside_checkout(entry)
    )
    env["ROS_HOME"] = str(tmp_path / "ros_home")
    env["COLCON_HOME"] = str(tmp_path / "colcon_home")
    return env


Run = Callable[..., subprocess.CompletedProcess[str]]


def _run(
    argv: Sequence[str | os.PathLike[str]],
    env: Mapping[str, str],
    cwd: Path | None = None,
    timeout: float = 240.0,
) -> subprocess.CompletedProcess[str]:
    env = dict(env)
    if cwd is not None:
        env["PWD"] = str(cwd)  # catkin_make takes its workspace from PWD, not getcwd()
    result = subprocess.run(
        [os.fspath(arg) for arg in argv],
        env=env,
        cwd=cwd,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    if result.returncode != 0:
        pytest.fail(
            f"{shlex.join(result.args)} exited {result.returncode}\n"
            f"--- stdout (tail) ---\n{result.stdout[-6000:]}\n"
            f"--- stderr (tail) ---\n{result.stderr[-6000:]}"
        )
    return result


@pytest.fixture
def run() -> Run:
    """``run(argv, env, cwd=None, timeout=240)``: run a command; fail the test with its output.

    Returns the ``CompletedProcess`` with text stdout/stderr.
    """
    return _run


@pytest.fixture
def in_workspace() -> Callable[[Path, str, Mapping[str, str]], list[str]]:
    """``in_workspace(setup_bash, commands, env)``: run bash commands after sourcing a setup file.

    Returns the output lines. Commands run with ``set -euo pipefail``.
    """

    def source_and_run(setup: Path, commands: str, env: Mapping[str, str]) -> list[str]:
        script = f"set -eo pipefail\nsource {shlex.quote(str(setup))}\nset -u\n{commands}"
        result = _run(["bash", "-c", script], env=env, timeout=120.0)
        return result.stdout.splitlines()

    return source_and_run
