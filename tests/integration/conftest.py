"""Integration tier: every test here is marked ``integration``; build helpers as fixtures."""

from __future__ import annotations

import os
import shlex
import subprocess
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.integration.failures import FAILED_CALL

if TYPE_CHECKING:
    from tests.integration.workspaces import CatkinWorkspace

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


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> object:
    """Note on the test whether its body failed (a fixture then gathers what explains it)."""
    report = yield
    if call.when == "call":
        item.stash[FAILED_CALL] = bool(getattr(report, "failed", False))
    return report


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test below this folder ``integration``."""
    for item in items:
        if HERE in Path(str(item.path)).resolve().parents:
            item.add_marker(pytest.mark.integration)


def _in_a_fresh_shell(entry: str) -> bool:
    """Whether a PATH entry stays in a ROS user's fresh shell on Debian.

    Entries in the checkout (scripts/, build/, .venv/bin, even through a symlink) go, and so
    does any other folder with a ``python3`` (a venv, pyenv): on Debian ``python3`` is
    /usr/bin/python3, which installed entry scripts (``#!/usr/bin/env python3``) run with.
    """
    if not entry:
        return False
    path = Path(entry)
    for place in (path.absolute(), path.resolve()):
        if REPO_ROOT in (place, *place.parents):
            return False
    return entry in ("/usr/bin", "/bin") or not (path / "python3").exists()


def fresh_shell_env(home: Path) -> dict[str, str]:
    """The environment of a fresh shell: none of env.sh's or a workspace's settings.

    PATH keeps what :func:`_in_a_fresh_shell` keeps; ROS_HOME and COLCON_HOME are in ``home``.
    """
    env = {key: value for key, value in os.environ.items() if key not in WORKSPACE_VARIABLES}
    env["PATH"] = ":".join(
        entry for entry in os.environ.get("PATH", "").split(":") if _in_a_fresh_shell(entry)
    )
    env["ROS_HOME"] = str(home / "ros_home")
    env["COLCON_HOME"] = str(home / "colcon_home")
    return env


@pytest.fixture
def clean_env(tmp_path: Path) -> dict[str, str]:
    """:func:`fresh_shell_env` with its homes in the test's ``tmp_path``."""
    return fresh_shell_env(tmp_path)


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


def run_in_workspace(
    setup: Path, commands: str, env: Mapping[str, str], cwd: Path | None = None
) -> list[str]:
    """Run bash ``commands`` after sourcing ``setup``; fail the test if they fail.

    Returns the output lines. Commands run with ``set -euo pipefail``.
    """
    script = f"set -eo pipefail\nsource {shlex.quote(str(setup))}\nset -u\n{commands}"
    result = _run(["bash", "-c", script], env=env, cwd=cwd, timeout=120.0)
    return result.stdout.splitlines()


@pytest.fixture
def in_workspace() -> Callable[[Path, str, Mapping[str, str]], list[str]]:
    """``in_workspace(setup_bash, commands, env)``: :func:`run_in_workspace` as a fixture."""
    return run_in_workspace


run_command = _run  # for module-scoped fixtures, which cannot use the ``run`` fixture


@pytest.fixture(scope="session")
def catkin_ws(tmp_path_factory: pytest.TempPathFactory) -> CatkinWorkspace:
    """The checkout built by ``catkin_make`` and ``catkin_make install``, once per session.

    Shared by the build, install-space and rostest tests (see workspaces.py).
    """
    from tests.integration.workspaces import build_catkin_workspace  # it imports this module

    return build_catkin_workspace(tmp_path_factory.mktemp("catkin_ws"))
