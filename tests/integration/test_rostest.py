"""The rostest files in test/ pass under rostest's own runner, as ROS users run them.

``catkin_make run_tests`` runs every one of them (``add_rostest`` in CMakeLists.txt), once, in
the session's catkin workspace; each file's results are then checked on their own: rostest's
report of the file and the report of its check node, so a file whose check node never ran
fails instead of passing with nothing counted. ``rostest rosmc server.test`` runs once more
the way the docs show it. Each run starts its own master on a free port.
"""

from __future__ import annotations

import os
import subprocess
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import pytest

from tests.integration.conftest import run_command
from tests.integration.workspaces import JOBS, CatkinWorkspace

REPO_ROOT = Path(__file__).resolve().parents[2]
TEST_FILES = sorted(path.name for path in (REPO_ROOT / "test").glob("*.test"))

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def test_results(catkin_ws: CatkinWorkspace, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``catkin_make run_tests`` in the session's workspace; the folder of its results."""
    journals = tmp_path_factory.mktemp("rostest_journals")
    env = {**catkin_ws.env, "ROSMC_TEST_DIR": str(journals)}
    results = catkin_ws.root / "build" / "test_results"
    run_command(["catkin_make", "run_tests", JOBS], env, cwd=catkin_ws.root, timeout=600)
    summary = run_command(["catkin_test_results", results], env)
    assert "0 errors, 0 failures" in summary.stdout, summary.stdout
    return results / "rosmc"


def test_every_node_has_a_rostest_file() -> None:
    assert {"server.test", "executor.test", "sim.test", "markers.test"} <= set(TEST_FILES)


@pytest.mark.parametrize("test_file", TEST_FILES)
def test_run_tests_runs_the_rostest_file(test_file: str, test_results: Path) -> None:
    stem = Path(test_file).stem
    assert _count(test_results / f"rostest-test_{stem}.xml") == (1, 0), "rostest's own report"
    for name in _check_names(REPO_ROOT / "test" / test_file):
        tests, bad = _count(test_results / f"rosunit-{name}.xml")
        assert tests >= 1 and bad == 0, (name, tests, bad)


def test_rostest_runs_a_file_as_the_docs_show(tmp_path: Path) -> None:
    env = {
        **os.environ,
        "ROS_HOME": str(tmp_path / "ros_home"),
        "ROSMC_TEST_DIR": str(tmp_path / "journal"),
    }
    env.pop("ROS_MASTER_URI", None)  # rostest starts its own master on a free port
    completed = subprocess.run(
        ["rostest", "rosmc", "server.test"],
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


def _check_names(test_file: Path) -> list[str]:
    """The test-name of every check node a .test file starts."""
    root = ElementTree.parse(test_file).getroot()
    return [str(node.get("test-name")) for node in root.iter("test")]


def _count(report: Path) -> tuple[int, int]:
    """(tests, failures + errors) of one JUnit XML report."""
    assert report.is_file(), f"no report {report.name}"
    root = ElementTree.parse(report).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    tests = sum(int(suite.get("tests", 0)) for suite in suites)
    bad = sum(int(suite.get("failures", 0)) + int(suite.get("errors", 0)) for suite in suites)
    return tests, bad
