"""The complete example of docs/writing-skills.md, run as the guide says.

The guide's library and module are written to a folder, the mission server reads the
library, and the guide's own shell command starts the robot's executor there; an
operator then runs the example skill and sees its progress and outcome.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from rosmc_server.core import SkillStatus
from tests.conftest import RosMaster
from tests.guide_blocks import blocks, write_files
from tests.integration.executor_fixtures import Operator, RosmcSystem, stop_process

pytestmark = pytest.mark.integration


def test_the_guide_example_robot_runs_its_skill(ros_master: RosMaster, tmp_path: Path) -> None:
    files = write_files(tmp_path)
    [command] = [line for line in blocks("bash")[0].splitlines() if line.strip()]
    system = RosmcSystem(ros_master.env, tmp_path / "system", library=files["sweeper_lab.yaml"])
    system.start_server()
    with (tmp_path / "executor.log").open("wb") as log:
        executor = subprocess.Popen(
            ["bash", "-c", command],
            cwd=tmp_path,
            env=dict(ros_master.env),
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    operator = Operator()
    try:
        operator.wait_links(["sweeper1"], timeout=60.0)
        sweep = operator.add("sweeper1", "sweep", {"dwell": 0.3})
        operator.sync("sweeper1")
        operator.start("sweeper1")
        state = operator.wait_status([sweep], SkillStatus.SUCCESS)
        assert state.skill(sweep).status_text == "swept 3 corners"
        # Progress reaches the ground paced (the newest text once a second): the first and
        # the last text before the finish always, in the order said.
        operator.events.wait_went(sweep, SkillStatus.SUCCESS)  # and every event before it
        said = [text for text in operator.status_texts(sweep) if text.startswith("corner")]
        assert said[0] == "corner 1 of 3 at (0.0, 0.0)", said
        assert said[-1] == "corner 3 of 3 at (2.0, 2.0)" and said == sorted(said), said
    finally:
        operator.close()
        stop_process(executor)
        system.close()
        print((tmp_path / "executor.log").read_text(errors="replace")[-3000:])
