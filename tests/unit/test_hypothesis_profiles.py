"""The suite's hypothesis profiles (tests/conftest.py), chosen with ``HYPOTHESIS_PROFILE``."""

from __future__ import annotations

import os
import re
import subprocess
import sys

from hypothesis import settings

from tests.conftest import HYPOTHESIS_PROFILES, REPO_ROOT

PROPERTY = "tests/unit/test_params.py::test_the_quick_path_answers_as_the_full_check"


def run_pytest(profile: str, *args: str) -> subprocess.CompletedProcess[str]:
    """This suite's pytest under ``profile``, from the repository root."""
    env = dict(os.environ, HYPOTHESIS_PROFILE=profile)
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:randomly", *args],
        cwd=REPO_ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )


def test_the_named_profile_is_in_use() -> None:
    name = os.environ.get("HYPOTHESIS_PROFILE", "quick")
    assert settings.default.max_examples == HYPOTHESIS_PROFILES[name].max_examples
    assert settings.default.deadline is None  # a busy machine may stall any example


def test_thorough_tries_many_more_examples_than_quick() -> None:
    quick, thorough = HYPOTHESIS_PROFILES["quick"], HYPOTHESIS_PROFILES["thorough"]
    assert thorough.max_examples >= 10 * quick.max_examples


def test_a_property_test_that_names_no_count_takes_the_profiles() -> None:
    result = run_pytest("quick", "--hypothesis-show-statistics", PROPERTY)
    assert result.returncode == 0, result.stdout + result.stderr
    stopped = re.findall(r"Stopped because settings\.max_examples=(\d+)", result.stdout)
    assert stopped == [str(HYPOTHESIS_PROFILES["quick"].max_examples)], result.stdout


def test_an_unknown_profile_is_refused_in_one_sentence() -> None:
    result = run_pytest("nightly", "--collect-only", PROPERTY)
    assert result.returncode != 0
    assert "HYPOTHESIS_PROFILE='nightly' is not one of: quick, thorough" in result.stderr
