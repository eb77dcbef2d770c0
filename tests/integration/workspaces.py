"""Workspaces built from the checkout the way a ROS user builds them, for the build tests.

Each starts from a fresh shell's environment (no env.sh) and skips the C++ and Lisp messages,
which nothing here uses (the full generation is built by `make setup` and by the standalone
build test): that saves about 40 %.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

from tests.integration.conftest import fresh_shell_env, run_command

REPO_ROOT = Path(__file__).resolve().parents[2]
SYSTEM_PYTHON = "/usr/bin/python3"
JOBS = f"-j{os.cpu_count() or 1}"
PYTHON_MESSAGES_ONLY = {"ROS_LANG_DISABLE": "gencpp:genlisp:geneus:gennodejs"}


@dataclass(frozen=True)
class Workspace:
    """A workspace built from a fresh shell: where its setup files are, and that shell's env."""

    setup: Path  # the setup.bash to source
    prefix: Path  # where the package's lib/ and share/ are
    env: dict[str, str]

    @property
    def share(self) -> Path:
        return self.prefix / "share" / "rosmc"


@dataclass(frozen=True)
class CatkinWorkspace:
    """A catkin workspace whose src/rosmc links to the checkout, built with catkin_make."""

    root: Path
    env: dict[str, str]

    @property
    def source(self) -> Path:
        return self.root / "src" / "rosmc"

    @property
    def devel(self) -> Path:
        return self.root / "devel"

    @property
    def install(self) -> Workspace:
        return Workspace(self.root / "install" / "setup.bash", self.root / "install", self.env)


def build_catkin_workspace(root: Path) -> CatkinWorkspace:
    """``catkin_make`` then ``catkin_make install`` in ``root``, whose src/rosmc is the checkout."""
    env = {**fresh_shell_env(root), **PYTHON_MESSAGES_ONLY}
    (root / "src").mkdir()
    (root / "src" / "rosmc").symlink_to(REPO_ROOT, target_is_directory=True)
    run_command(["catkin_make", f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}", JOBS], env, cwd=root)
    run_command(["catkin_make", "install", JOBS], env, cwd=root)
    return CatkinWorkspace(root, env)


def build_colcon_workspace(root: Path) -> Workspace:
    """``colcon build`` of the checkout in ``root`` (colcon's default isolated layout)."""
    env = {**fresh_shell_env(root), **PYTHON_MESSAGES_ONLY}
    colcon = Path(sys.executable).parent / "colcon"
    assert colcon.is_file(), "colcon is installed into the venv from requirements.txt"
    install = root / "install"
    run_command(
        [
            colcon,
            "--log-base",
            root / "log",
            "build",
            "--base-paths",
            REPO_ROOT,
            "--build-base",
            root / "build",
            "--install-base",
            install,
            "--cmake-args",
            f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}",
        ],
        env,
        cwd=root,
    )
    return Workspace(install / "setup.bash", install / "rosmc", env)
