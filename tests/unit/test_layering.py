"""Layering: no ``core`` package imports ROS, generated messages, Qt or (outside the sim) pybullet.

DESIGN §2: ``core/`` never imports rospy, genpy, generated messages, Qt or
pybullet (the simulation core may use pybullet); ``ros/`` is the only place
that imports rospy. The scanner reads every module with :mod:`ast`, so a
forbidden import is found even where it would never run (inside a function or
an ``if``). A second test imports every core package with the forbidden
modules blocked, which also catches imports that happen indirectly.
"""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

# Top-level modules a core package must not import.
FORBIDDEN = {
    "rospy": "rospy",
    "genpy": "generated-message runtime",
    "roslib": "roslib",
    "rosmc": "generated messages (rosmc.msg / rosmc.srv)",
    "PyQt5": "Qt",
    "PyQt6": "Qt",
    "PySide2": "Qt",
    "PySide6": "Qt",
    "python_qt_binding": "Qt",
    "Qt": "Qt",
    "pybullet": "pybullet",
    "pybullet_data": "pybullet",
}
# Only the simulation core may use pybullet.
PYBULLET_ALLOWED = ("rosmc_sim/core/",)
PYBULLET = {"pybullet", "pybullet_data"}
# Dynamic imports with a literal module name are checked too.
IMPORT_FUNCTIONS = {"import_module", "__import__"}


@dataclass(frozen=True)
class Violation:
    """One forbidden import."""

    path: str
    line: int
    module: str
    why: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line} imports {self.module} ({self.why})"


def core_modules(root: Path = REPO) -> list[Path]:
    """Every module of every ``core`` package of the repository's rosmc_* packages."""
    return sorted(
        path for path in root.glob("rosmc_*/**/core/**/*.py") if "__pycache__" not in path.parts
    )


def _module_name(path: Path, root: Path) -> list[str]:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return parts[:-1] if parts[-1] == "__init__" else parts


def _absolute(node: ast.ImportFrom, path: Path, root: Path) -> str:
    """The absolute module an ``from ... import`` names (resolving leading dots)."""
    if node.level == 0:
        return node.module or ""
    package = _module_name(path, root)
    if path.name != "__init__.py":
        package = package[:-1]
    base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
    return ".".join([*base, *([node.module] if node.module else [])])


def _imported(tree: ast.AST, path: Path, root: Path) -> list[tuple[int, str]]:
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            module = _absolute(node, path, root)
            found.append((node.lineno, module))
            # "from rosmc_server import ros" imports the ros layer too.
            found += [(node.lineno, f"{module}.{alias.name}") for alias in node.names]
        elif isinstance(node, ast.Call):
            func = node.func
            name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if name in IMPORT_FUNCTIONS and node.args:
                first = node.args[0]
                if isinstance(first, ast.Constant) and isinstance(first.value, str):
                    found.append((node.lineno, first.value))
    return found


def scan(path: Path, root: Path = REPO) -> list[Violation]:
    """The forbidden imports of one core module."""
    relative = path.relative_to(root).as_posix()
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    violations = []
    for line, module in _imported(tree, path, root):
        parts = module.split(".")
        top = parts[0]
        if top in FORBIDDEN:
            if top in PYBULLET and relative.startswith(PYBULLET_ALLOWED):
                continue
            violations.append(Violation(relative, line, module, FORBIDDEN[top]))
        elif top.startswith("rosmc_") and "ros" in parts[1:]:
            violations.append(Violation(relative, line, module, "the ROS adapter layer"))
    return violations


# -- the real check ------------------------------------------------------------------


def test_there_are_core_modules_to_scan() -> None:
    modules = {p.relative_to(REPO).as_posix() for p in core_modules()}
    expected = {
        f"rosmc_server/core/{name}.py"
        for name in (
            "errors",
            "params",
            "library",
            "model",
            "changes",
            "state",
            "barriers",
            "editing",
            "execution",
            "markers",
            "mission",
            "persistence",
        )
    }
    assert expected <= modules


def test_no_core_module_imports_ros_qt_or_pybullet() -> None:
    violations = [str(v) for path in core_modules() for v in scan(path)]
    assert violations == []


def test_core_packages_import_with_the_forbidden_modules_blocked() -> None:
    packages = sorted(
        {
            ".".join(_module_name(path.parent / "__init__.py", REPO))
            for path in core_modules()
            if (path.parent / "__init__.py").exists()
        }
    )
    modules = sorted(
        {
            ".".join(_module_name(path, REPO))
            for path in core_modules()
            if (path.parent / "__init__.py").exists()
            and not path.relative_to(REPO).as_posix().startswith(PYBULLET_ALLOWED)
        }
    )
    blocked = sorted(FORBIDDEN)
    program = textwrap.dedent(
        f"""
        import importlib, sys
        for name in {blocked!r}:
            sys.modules[name] = None  # importing it now raises ImportError
        for module in {modules!r}:
            importlib.import_module(module)
        """
    )
    assert packages, "no core packages found"
    result = subprocess.run(
        [sys.executable, "-c", program],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-2000:]


# -- the scanner catches what it should -----------------------------------------------


@pytest.fixture
def fake_repo(tmp_path: Path) -> Path:
    for package in ("rosmc_server/core", "rosmc_sim/core", "rosmc_server/ros"):
        (tmp_path / package).mkdir(parents=True)
        (tmp_path / package / "__init__.py").write_text("", encoding="utf-8")
    return tmp_path


BAD = [
    "import rospy",
    "import rospy as r",
    "from rospy import Publisher",
    "import genpy",
    "import roslib.message",
    "from rosmc.msg import Mission",
    "import rosmc.srv",
    "from rosmc import msg",
    "from PyQt5 import QtCore",
    "from PySide2.QtWidgets import QWidget",
    "from python_qt_binding.QtCore import Signal",
    "import pybullet",
    "import pybullet_data",
    "from ..ros import node",
    "from rosmc_server.ros.node import main",
    "from rosmc_server import ros",
    "importlib.import_module('rospy')",
    "__import__('PyQt5')",
    "def later():\n    import rospy",
    "if False:\n    import rospy",
    "try:\n    import rospy\nexcept ImportError:\n    rospy = None",
]


@pytest.mark.parametrize("source", BAD)
def test_scanner_catches_a_bad_import(fake_repo: Path, source: str) -> None:
    module = fake_repo / "rosmc_server" / "core" / "bad.py"
    module.write_text(source + "\n", encoding="utf-8")
    assert module in core_modules(fake_repo)
    violations = scan(module, fake_repo)
    assert len(violations) >= 1, source
    assert violations[0].path == "rosmc_server/core/bad.py"
    assert str(violations[0]).startswith("rosmc_server/core/bad.py:")


def test_scanner_self_test_import_rospy(fake_repo: Path) -> None:
    module = fake_repo / "rosmc_server" / "core" / "uses_ros.py"
    module.write_text('"""A core module that went wrong."""\n\nimport rospy\n', encoding="utf-8")
    (violation,) = scan(module, fake_repo)
    assert (violation.line, violation.module, violation.why) == (3, "rospy", "rospy")


GOOD = [
    "import yaml",
    "import math, json",
    "from . import model",
    "from .model import SkillStatus",
    "from ..core import errors",
    "from rosmc_server.core.errors import RosmcError",
    "import rosmc_server.core",
    "from rosmc_server.recording import topics",  # not the ros layer
    "import rospkg_like_name",
    "x = 'import rospy'",
    "# import rospy",
    "def f(importer):\n    return importer.import_module(name)",
]


@pytest.mark.parametrize("source", GOOD)
def test_scanner_allows_plain_python(fake_repo: Path, source: str) -> None:
    module = fake_repo / "rosmc_server" / "core" / "good.py"
    module.write_text(source + "\n", encoding="utf-8")
    assert scan(module, fake_repo) == []


def test_pybullet_only_in_the_sim_core(fake_repo: Path) -> None:
    sim = fake_repo / "rosmc_sim" / "core" / "world.py"
    sim.write_text("import pybullet\nimport pybullet_data\n", encoding="utf-8")
    assert scan(sim, fake_repo) == []
    sim.write_text("import pybullet\nimport rospy\n", encoding="utf-8")
    assert [v.module for v in scan(sim, fake_repo)] == ["rospy"]


def test_only_core_packages_are_scanned(fake_repo: Path) -> None:
    (fake_repo / "rosmc_server" / "ros" / "node.py").write_text("import rospy\n", encoding="utf-8")
    nested = fake_repo / "rosmc_server" / "executor" / "core"
    nested.mkdir(parents=True)
    (nested / "runner.py").write_text("import rospy\n", encoding="utf-8")
    found = [p.relative_to(fake_repo).as_posix() for p in core_modules(fake_repo)]
    assert "rosmc_server/ros/node.py" not in found
    assert "rosmc_server/executor/core/runner.py" in found
