"""rviz on the simulated site, for real: a true 3D GUI check of ``rviz/sim.rviz``.

A real master (the session's), the real sim node ``/rosmc/sim`` at a real-time factor of
20 with ``/use_sim_time`` set (as ``launch/sim.launch`` does), and real rviz under Xvfb
through ``tools/rviz_screenshot.py``, as a user runs it. The screenshot must show the site:
a 3D view in the config's background colour with many colours in it, the lander's Wi-Fi
circle in the colour the sim gives it (lines are unlit: the colour is exact up to the
blending of the marker's alpha over the background) and the brown of the obstacles (lit,
so only a hue). Afterwards no rviz or Xvfb of this test may be left running.

Skipped only when rviz, Xvfb or ImageMagick are not installed, and never under CI
(``CI`` set): ``make setup`` installs them.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import shutil
import subprocess
import sys
import time
import xmlrpc.client
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest
import yaml

from rosmc_server.core.views.vocabulary import PALETTE
from rosmc_sim.core.scenario import load_scenario
from rosmc_sim.ros.robot_state import MAP_FRAME, base_link
from rosmc_sim.ros.topics import WORLD_TOPIC, odom_topic
from tests.conftest import LaunchProcess, RosMaster

REPO = Path(__file__).resolve().parents[2]
TOOL = REPO / "tools" / "rviz_screenshot.py"
CONFIG = REPO / "rviz" / "sim.rviz"
SCENARIO = REPO / "rosmc_sim" / "scenarios" / "mars_sample_return.yaml"
GUI_PROGRAMS = ("rviz", "Xvfb", "import", "convert")
SIM_START_TIMEOUT = 60.0
CALLER = "/test_rviz"


def load_tool() -> ModuleType:
    """``tools/rviz_screenshot.py`` as a module (tools/ is not a package)."""
    spec = importlib.util.spec_from_file_location("rviz_screenshot", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def load_config() -> dict[str, Any]:
    """``rviz/sim.rviz`` as YAML."""
    config: dict[str, Any] = yaml.safe_load(CONFIG.read_text())
    return config


def displays(config: dict[str, Any], kind: str) -> list[dict[str, Any]]:
    """The displays of class ``rviz/<kind>``."""
    found: list[dict[str, Any]] = [
        d for d in config["Visualization Manager"]["Displays"] if d["Class"] == f"rviz/{kind}"
    ]
    return found


def background(config: dict[str, Any]) -> tuple[int, int, int]:
    """The config's background colour."""
    text = config["Visualization Manager"]["Global Options"]["Background Color"]
    red, green, blue = (int(part) for part in text.split(";"))
    return red, green, blue


def blended(rgba: tuple[float, float, float, float], under: tuple[int, int, int]) -> list[int]:
    """What an unlit marker colour with alpha looks like over ``under``."""
    alpha = rgba[3]
    return [round(255 * c * alpha + u * (1 - alpha)) for c, u in zip(rgba[:3], under, strict=True)]


# -- the config, without a GUI ------------------------------------------------------------------
def test_the_config_shows_the_sims_topics_and_every_agent_in_the_map_frame() -> None:
    config = load_config()
    assert config["Visualization Manager"]["Global Options"]["Fixed Frame"] == MAP_FRAME
    assert [d["Marker Topic"] for d in displays(config, "MarkerArray")] == [WORLD_TOPIC]
    scenario = load_scenario(SCENARIO)
    robots = [robot.name for robot in scenario.robots]
    assert sorted(d["Topic"] for d in displays(config, "Odometry")) == sorted(
        odom_topic(robot) for robot in robots
    )
    agents = [*robots, "lander", *(box.name for box in scenario.boxes)]
    shown = {
        frame
        for tf in displays(config, "TF")
        if tf["Show Names"]
        for frame, state in tf["Frames"].items()
        if frame != "All Enabled" and state["Value"]
    }
    assert shown == {base_link(agent) for agent in agents}
    assert sum(background(config)) < 3 * 64, "the background is dark"


def test_view_sim_launch_opens_the_config(tmp_path: Path) -> None:
    def rviz_args(*launch_args: str) -> str:
        result = subprocess.run(
            ["roslaunch", "--args", "/rviz_sim", "rosmc", "view_sim.launch", *launch_args],
            capture_output=True,
            text=True,
            timeout=60,
            check=True,
        )
        return result.stdout.strip()

    assert rviz_args().split()[1:3] == ["-d", str(CONFIG)]
    other = tmp_path / "other.rviz"
    assert rviz_args(f"rviz_config:={other}").split()[1:3] == ["-d", str(other)]


# -- rviz under Xvfb ----------------------------------------------------------------------------
@pytest.fixture
def gui_programs() -> None:
    """Skip when rviz, Xvfb or ImageMagick are missing; under CI, fail instead."""
    missing = [name for name in GUI_PROGRAMS if shutil.which(name) is None]
    if missing and os.environ.get("CI"):
        pytest.fail(f"not installed under CI (make setup installs them): {missing}")
    if missing:
        pytest.skip(f"not installed (make setup installs them): {missing}")


def _publishers(master: RosMaster, topic: str) -> list[str]:
    publishers, _, _ = master.proxy().getSystemState(CALLER)[2]
    return next((nodes for name, nodes in publishers if name == topic), [])


@pytest.fixture
def sim(ros_master: RosMaster, launch_process: LaunchProcess) -> Iterator[None]:
    """The sim node at a real-time factor of 20 under sim time, publishing the site."""
    proxy = ros_master.proxy()
    proxy.setParam(CALLER, "/use_sim_time", True)
    try:
        node = launch_process(
            [sys.executable, str(REPO / "scripts" / "sim_node"), "_real_time_factor:=20"],
            env=ros_master.env,
            name="sim_node",
            cwd=REPO,
        )
        deadline = time.monotonic() + SIM_START_TIMEOUT
        while not all(_publishers(ros_master, t) for t in (WORLD_TOPIC, "/clock", "/tf")):
            assert node.poll() is None, node.log()[-3000:]
            assert time.monotonic() < deadline, f"the sim did not start:\n{node.log()[-3000:]}"
            time.sleep(0.1)
        yield
    finally:
        for name in ("/use_sim_time", "/rosmc/sim"):
            with contextlib.suppress(xmlrpc.client.Error):
                proxy.deleteParam(CALLER, name)


def _leftovers(master_uri: str) -> list[str]:
    """rviz or Xvfb processes started for ``master_uri`` that still run."""
    found = []
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        with contextlib.suppress(OSError):
            if (proc / "comm").read_text().strip() not in ("rviz", "Xvfb"):
                continue
            if f"ROS_MASTER_URI={master_uri}".encode() in (proc / "environ").read_bytes():
                found.append(f"{proc.name}: {(proc / 'cmdline').read_bytes()!r}")
    return found


@pytest.mark.usefixtures("gui_programs")
def test_rviz_that_dies_at_start_up_is_started_again(ros_master: RosMaster, tmp_path: Path) -> None:
    """The first rviz dies of SIGSEGV before it draws (as Mesa's now and then does)."""
    wrappers, crashed = tmp_path / "bin", tmp_path / "crashed"
    wrappers.mkdir()
    rviz = wrappers / "rviz"
    real = shutil.which("rviz")
    rviz.write_text(
        f"#!/bin/sh\nif [ ! -e {crashed} ]; then touch {crashed}; kill -SEGV $$; fi\n"
        f'exec {real} "$@"\n'
    )
    rviz.chmod(0o755)
    env = {**ros_master.env, "PATH": f"{wrappers}{os.pathsep}{ros_master.env['PATH']}"}
    result = subprocess.run(
        [
            *(sys.executable, str(TOOL), "--config", str(CONFIG), "--output", tmp_path / "a.png"),
            *("--timeout", "40", "--settle", "0", "--attempts", "2", "--min-colors", "8"),
        ],  # no sim: the grid alone counts as drawn
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert crashed.exists(), "the wrapper did not run"
    assert result.returncode == 0, f"{result.stdout}\n{result.stderr}"
    assert "rviz started 2 time(s)" in result.stdout, result.stdout


@pytest.mark.usefixtures("gui_programs", "sim")
def test_rviz_draws_the_site_under_xvfb(ros_master: RosMaster, tmp_path: Path) -> None:
    config = load_config()
    wifi = blended(PALETTE["wifi"], background(config))
    score = blended(PALETTE["score"], background(config))  # the score text over the lander
    output, log = tmp_path / "sim.png", tmp_path / "rviz.log"
    started = time.monotonic()
    result = subprocess.run(
        [
            sys.executable,
            str(TOOL),
            "--config",
            str(CONFIG),
            "--output",
            str(output),
            "--timeout",
            "20",
            "--settle",
            "2",
            "--expect-fraction",  # the score's letters are small (the whole site shows)
            "0.0002",
            "--expect-color",
            ",".join(map(str, wifi)),
            "--expect-color",
            ",".join(map(str, score)),
            "--log",
            str(log),
        ],
        env=ros_master.env,
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    elapsed = time.monotonic() - started
    rviz_log = log.read_text(errors="replace")[-3000:] if log.exists() else "<no log>"
    assert result.returncode == 0, f"{result.stdout}\n{result.stderr}\n--- rviz ---\n{rviz_log}"
    assert not _leftovers(ros_master.uri), _leftovers(ros_master.uri)
    print(f"screenshot in {elapsed:.1f} s: {result.stdout.strip()}")

    tool = load_tool()
    ppm = subprocess.run(
        ["convert", str(output), "-depth", "8", "ppm:-"], capture_output=True, check=True
    ).stdout
    shot = tool.parse_ppm(ppm)
    assert (shot.width, shot.height) == (1600, 1000)
    view = shot.view(background(config))
    assert view is not None, "no 3D view of the config's background colour"
    assert view.width > 900 and view.height > 700, "the 3D view is small"
    assert view.distinct_colors() >= 100, "a few colours only: not a rendered scene"
    assert view.fraction_near(tuple(wifi), 24) > 0.0005, "no Wi-Fi coverage circle"
    assert view.fraction_near(tuple(score), 24) > 0.0001, "no science score over the lander"
    red, green, blue = (view.pixels[..., i].astype(np.int16) for i in range(3))
    brown = (red > green) & (green > blue) & (red - blue >= 25) & (red >= 60)
    assert brown.mean() > 0.003, "no obstacles (brown, lit) on the site"
