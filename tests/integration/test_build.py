"""The package builds three ways, and each result finds its messages, scripts and launch files.

Every build goes to a temporary folder and starts from a fresh shell's environment (no env.sh),
exactly as docs/integrator-guide.md's "Building" section tells a user to do it.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
SYSTEM_PYTHON = "/usr/bin/python3"
JOBS = f"-j{os.cpu_count() or 1}"
DATA_SUFFIXES = {".yaml", ".yml", ".json", ".xml", ".rviz", ".ui", ".png", ".svg", ".urdf"}

# The workspace builds skip the C++ and Lisp messages, which nothing here uses: the full
# generation is built by `make setup` and by test_standalone_cmake_build. Saves ~40 %.
PYTHON_MESSAGES_ONLY = {"ROS_LANG_DISABLE": "gencpp:genlisp:geneus:gennodejs"}

pytestmark = pytest.mark.slow


def python_packages() -> list[str]:
    """Every rosmc_* package and subpackage of the checkout, dotted."""
    return sorted(
        ".".join(init.parent.relative_to(REPO_ROOT).parts)
        for init in REPO_ROOT.glob("rosmc_*/**/__init__.py")
        if "__pycache__" not in init.parts
    )


def package_files() -> list[str]:
    """Modules and data files below the rosmc_* packages, relative to the repo root."""
    return sorted(
        path.relative_to(REPO_ROOT).as_posix()
        for path in REPO_ROOT.glob("rosmc_*/**/*")
        if path.is_file()
        and "__pycache__" not in path.parts
        and (path.suffix == ".py" or path.suffix in DATA_SUFFIXES)
        and path.parts[len(REPO_ROOT.parts)] != "rosmc_msgs"
    )


def entry_scripts() -> list[str]:
    return sorted(path.name for path in (REPO_ROOT / "scripts").iterdir() if path.is_file())


def launch_files() -> list[str]:
    return sorted(path.name for path in (REPO_ROOT / "launch").glob("*.launch"))


def top_level_imports() -> str:
    names = ["rosmc.msg", "rosmc.srv", *(name for name in python_packages() if "." not in name)]
    return f"import {', '.join(names)}; print(rosmc.msg.__file__)"


# `sed -n 1p` reads everything: piped into `head -n 1`, rosmsg/rossrv die of a broken pipe now
# and then, which fails the script under pipefail.
PRINT_LOOKUPS = f"""
rospack find rosmc
rosrun --prefix echo rosmc rosmc_demo
roslaunch --files rosmc mission_server.launch
roslaunch --nodes rosmc mission_server.launch
{SYSTEM_PYTHON} -c '{top_level_imports()}'
rosmsg show rosmc/Pose6D | sed -n 1p
rossrv show rosmc/AddSkill | sed -n 1p
"""

# What an entry script does first: find the project's PyPI packages (rosmc_server/venv.py),
# then import them. Prints the venv it used and where mcap and pybullet came from.
PYPI_IMPORTS = f"""{SYSTEM_PYTHON} -c 'from rosmc_server.venv import use_project_venv
print(use_project_venv())
import mcap, pybullet, rosbags
print(mcap.__file__)'
"""


def check_lookups(lines: list[str], share: Path, script: Path, launch: Path, python: Path) -> None:
    """Check the output of PRINT_LOOKUPS, one line each."""
    assert lines[0] == str(share)
    assert lines[1] == str(script)
    assert lines[2] == str(launch / "mission_server.launch")
    assert lines[3] == "/rosmc/mission_server"
    assert Path(lines[4]).is_relative_to(python), lines[4]
    assert lines[5:7] == ["float64 x", "uint64 base_revision"], lines[5:]


def check_pypi_packages(setup: Path, env: dict[str, str], in_workspace, venv: Path) -> None:
    """Outside env.sh an entry script finds the PyPI packages in ``venv``."""
    lines = in_workspace(setup, PYPI_IMPORTS, env)
    assert lines[0] == str(venv), lines
    assert Path(lines[1]).is_relative_to(venv), lines


def test_standalone_cmake_build(tmp_path: Path, clean_env, run, in_workspace) -> None:
    build = tmp_path / "build"
    run(["cmake", "-S", REPO_ROOT, "-B", build, f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}"], clean_env)
    run(["make", "-C", build, JOBS], clean_env)

    devel = build / "devel"
    lines = in_workspace(devel / "setup.bash", PRINT_LOOKUPS, clean_env)
    check_lookups(
        lines,
        share=REPO_ROOT,
        script=devel / "lib" / "rosmc" / "rosmc_demo",  # catkin's devel-space relay
        launch=REPO_ROOT / "launch",
        python=devel / "lib" / "python3" / "dist-packages",
    )
    check_pypi_packages(devel / "setup.bash", clean_env, in_workspace, REPO_ROOT / ".venv")
    if (REPO_ROOT / "rosmc_server" / "demo.py").exists():
        # The relay runs the script in scripts/ with Debian's python.
        lines = in_workspace(devel / "setup.bash", "rosrun rosmc rosmc_demo --help", clean_env)
        assert lines[0].startswith("usage: rosmc_demo")


def test_catkin_make_devel_and_install(tmp_path: Path, clean_env, run, in_workspace) -> None:
    clean_env.update(PYTHON_MESSAGES_ONLY)
    workspace = tmp_path / "ws"
    (workspace / "src").mkdir(parents=True)
    source = workspace / "src" / "rosmc"
    source.symlink_to(REPO_ROOT, target_is_directory=True)

    run(["catkin_make", f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}", JOBS], clean_env, cwd=workspace)
    devel = workspace / "devel"
    lines = in_workspace(devel / "setup.bash", PRINT_LOOKUPS, clean_env)
    check_lookups(
        lines,
        share=source,
        script=devel / "lib" / "rosmc" / "rosmc_demo",
        launch=source / "launch",
        python=devel / "lib" / "python3" / "dist-packages",
    )
    check_pypi_packages(devel / "setup.bash", clean_env, in_workspace, REPO_ROOT / ".venv")

    run(["catkin_make", "install", JOBS], clean_env, cwd=workspace)
    install = workspace / "install"
    share = install / "share" / "rosmc"
    lines = in_workspace(install / "setup.bash", PRINT_LOOKUPS, clean_env)
    check_install_space(lines, install, share, install / "lib" / "rosmc")
    # An install space has no checkout beside it: ROSMC_VENV names the venv.
    venv_env = {**clean_env, "ROSMC_VENV": str(REPO_ROOT / ".venv")}
    check_pypi_packages(install / "setup.bash", venv_env, in_workspace, REPO_ROOT / ".venv")


def check_install_space(lines: list[str], prefix: Path, share: Path, bin_dir: Path) -> None:
    """An install space holds every script, launch file, module and data file of the repo."""
    site = prefix / "lib" / "python3" / "dist-packages"
    check_lookups(lines, share, bin_dir / "rosmc_demo", share / "launch", site)
    for name in entry_scripts():
        script = bin_dir / name
        assert script.is_file() and os.access(script, os.X_OK), script
        assert script.read_text().startswith("#!/usr/bin/env python3\n"), script
    for name in launch_files():
        assert (share / "launch" / name).is_file(), name
    for rel in package_files():
        assert (site / rel).is_file(), f"{rel} is not installed"
    if (REPO_ROOT / "rosmc_server" / "config").is_dir():
        assert (share / "rosmc_server" / "config").is_dir()


def test_colcon_build(tmp_path: Path, clean_env, run, in_workspace) -> None:
    clean_env.update(PYTHON_MESSAGES_ONLY)
    colcon = Path(sys.executable).parent / "colcon"
    assert colcon.is_file(), "colcon is installed into the venv from requirements.txt"
    install = tmp_path / "install"
    run(
        [
            colcon,
            "--log-base",
            tmp_path / "log",
            "build",
            "--base-paths",
            REPO_ROOT,
            "--build-base",
            tmp_path / "build",
            "--install-base",
            install,
            "--cmake-args",
            f"-DPYTHON_EXECUTABLE={SYSTEM_PYTHON}",
        ],
        clean_env,
        cwd=tmp_path,
    )
    prefix = install / "rosmc"  # colcon's default isolated layout
    lines = in_workspace(install / "setup.bash", PRINT_LOOKUPS, clean_env)
    check_install_space(lines, prefix, prefix / "share" / "rosmc", prefix / "lib" / "rosmc")
