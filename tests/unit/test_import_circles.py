"""No import circles in the rosmc_* packages, and the finder finds the ones it should."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.unit.import_circles import import_circles, imported_modules


def test_no_import_circles() -> None:
    assert [sorted(c) for c in import_circles()] == [], "modules that import each other"


# -- the finder on small made-up repositories ---------------------------------------------


def _repo(root: Path, modules: dict[str, str]) -> Path:
    for relative, source in modules.items():
        path = root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        for folder in path.relative_to(root).parents:
            init = root / folder / "__init__.py"
            if folder != Path(".") and not init.exists():
                init.write_text("", encoding="utf-8")
        path.write_text(source + "\n", encoding="utf-8")
    return root


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ("from . import b", "from . import a"),
        ("from .b import f", "from .a import g"),
        ("import rosmc_server.core.b", "from rosmc_server.core import a"),
        ("from .b import f", "def later():\n    from .a import g"),  # lazy
        (
            "from .b import f",
            "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .a import A",
        ),
        ("from ..core import b", "from . import a"),
    ],
)
def test_finds_a_circle_of_two(tmp_path: Path, a: str, b: str) -> None:
    root = _repo(tmp_path, {"rosmc_server/core/a.py": a, "rosmc_server/core/b.py": b})
    assert import_circles(root) == [frozenset({"rosmc_server/core/a.py", "rosmc_server/core/b.py"})]


def test_finds_a_longer_circle_and_only_its_members(tmp_path: Path) -> None:
    root = _repo(
        tmp_path,
        {
            "rosmc_server/ros/a.py": "from .b import f",
            "rosmc_server/ros/b.py": "from rosmc_server.core.c import g",
            "rosmc_server/core/c.py": "from ..ros import a\nfrom . import d",
            "rosmc_server/core/d.py": "import json",
        },
    )
    expected = {"rosmc_server/ros/a.py", "rosmc_server/ros/b.py", "rosmc_server/core/c.py"}
    assert import_circles(root) == [frozenset(expected)]


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ("from . import b", "import json"),
        ("from .b import f", "from .c import g"),
        ("x = 'from .b import f'", "from .a import g"),
        ("from rosmc_server.core import b", "import rosmc_nothing"),
    ],
)
def test_no_circle_without_one(tmp_path: Path, a: str, b: str) -> None:
    root = _repo(
        tmp_path,
        {"rosmc_server/core/a.py": a, "rosmc_server/core/b.py": b, "rosmc_server/core/c.py": ""},
    )
    assert import_circles(root) == []


def test_a_name_from_a_package_is_its_init_and_a_submodule_is_itself(tmp_path: Path) -> None:
    root = _repo(
        tmp_path,
        {
            "rosmc_server/core/__init__.py": "from .model import Thing",
            "rosmc_server/core/model.py": "",
            "rosmc_server/ros/node.py": "from ..core import Thing\nfrom ..core import model",
        },
    )
    found = imported_modules(root / "rosmc_server/ros/node.py", root)
    assert found == {"rosmc_server/core/__init__.py", "rosmc_server/core/model.py"}
