"""The rostest files in test/ pass under rostest's own runner, as ROS users run them.

``rostest rosmc server.test`` (and executor, sim, markers) starts its own master on a free
port, launches the real nodes and runs a unittest node against them. Here each runs in a
private ROS_HOME and journal folder; the results XML rostest writes is checked too, so a file
whose test node never ran fails instead of passing with nothing counted.
"""

from __future__ import annotations

import os
import subprocess
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
TEST_FILES = sorted(path.name for path in (REPO_ROOT / "test").glob("*.test"))

pytestmark = pytest.mark.slow


def test_every_node_has_a_rostest_file() -> None:
    assert {"server.test", "executor.test", "sim.test", "markers.test"} <= set(TEST_FILES)


@pytest.mark.parametrize("test_file", TEST_FILES)
def test_rostest_file_passes(test_file: str, tmp_path: Path) -> None:
    results = tmp_path / "results"
    env = {
        **os.environ,
        "ROS_HOME": str(tmp_path / "ros_home"),
        "ROSMC_TEST_DIR": str(tmp_path / "journal"),
    }
    env.pop("ROS_MASTER_URI", None)  # rostest starts its own master on a free port
    completed = subprocess.run(
        ["rostest", "--results-base-dir", str(results), "rosmc", test_file],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    output = completed.stdout + completed.stderr
    assert completed.returncode == 0, output[-4000:]
    assert "RESULT: SUCCESS" in output, output[-4000:]
    counted = [_count(report) for report in results.rglob("*.xml")]
    assert counted, f"rostest wrote no results under {results}"
    tests = sum(count[0] for count in counted)
    failed = sum(count[1] for count in counted)
    assert tests > 1 and failed == 0, (tests, failed, output[-4000:])


def _count(report: Path) -> tuple[int, int]:
    """(tests, failures + errors) of one JUnit XML report."""
    root = ElementTree.parse(report).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    tests = sum(int(suite.get("tests", 0)) for suite in suites)
    bad = sum(int(suite.get("failures", 0)) + int(suite.get("errors", 0)) for suite in suites)
    return tests, bad
