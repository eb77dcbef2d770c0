"""The pre-commit hooks run what ``make lint`` runs, and keep commit subjects short.

``pre-commit`` itself is not part of .venv, so the config is read here as pre-commit reads
it: the lint hooks must run the Makefile's own commands, and the commit-msg hook's pattern
(a ``pygrep`` with ``--multiline``, which fails the commit on a match) must refuse a
subject of 72 characters or more and nothing else.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

REPO = Path(__file__).resolve().parents[2]


def hooks() -> dict[str, dict[str, Any]]:
    config = yaml.safe_load((REPO / ".pre-commit-config.yaml").read_text())
    return {hook["id"]: hook for repo in config["repos"] for hook in repo["hooks"]}


def test_the_lint_hooks_run_the_makefile_lint() -> None:
    makefile = (REPO / "Makefile").read_text()
    found = hooks()
    assert "ruff check ." in makefile and "ruff check" in found["ruff-check"]["entry"]
    assert "ruff format --check ." in makefile
    assert "ruff format --check" in found["ruff-format"]["entry"]
    assert "mypy --strict $(PACKAGES)" in makefile
    mypy = found["mypy"]
    assert "mypy --strict $(dirname rosmc_*/__init__.py)" in mypy["entry"]
    assert mypy["pass_filenames"] is False  # the whole packages, as make lint checks them


def test_the_commit_message_hook_refuses_long_subjects_only() -> None:
    hook = hooks()["commit-subject"]
    assert hook["language"] == "pygrep" and hook["args"] == ["--multiline"]
    assert hook["stages"] == ["commit-msg"]
    # pre-commit's pygrep compiles the entry as bytes with MULTILINE | DOTALL for --multiline
    pattern = re.compile(hook["entry"].encode(), re.MULTILINE | re.DOTALL)

    def refused(message: str) -> bool:
        return pattern.search(message.encode()) is not None

    body = "A body line may be as long as it needs to be, " * 3
    assert not refused("x" * 71 + "\n\n" + body + "\n")
    assert refused("x" * 72 + "\n\nbody\n")
    assert not refused("Short subject\n")
