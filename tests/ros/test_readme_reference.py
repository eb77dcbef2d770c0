"""README.md's message and service reference matches rosmc_msgs/ (regenerate with --write)."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path
from types import ModuleType

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
TOOL = REPO_ROOT / "tools" / "gen_msg_reference.py"


@pytest.fixture(scope="module")
def tool() -> ModuleType:
    spec = importlib.util.spec_from_file_location("gen_msg_reference", TOOL)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    try:
        spec.loader.exec_module(module)
    finally:
        del sys.modules[spec.name]
    return module


@pytest.fixture(scope="module")
def readme_section(tool: ModuleType) -> str:
    text = (REPO_ROOT / "README.md").read_text()
    start, end = text.index(tool.BEGIN), text.index(tool.END)
    return text[start : end + len(tool.END)] + "\n"


def test_readme_reference_is_generated_from_the_definitions(tool, readme_section) -> None:
    assert readme_section == tool.generate(), (
        "README.md's message reference is out of date: python tools/gen_msg_reference.py --write"
    )


def test_every_definition_has_a_section(readme_section) -> None:
    names = [p.stem for p in sorted((REPO_ROOT / "rosmc_msgs").glob("*/*.[ms][sr][gv]"))]
    assert len(names) >= 40
    headings = set(re.findall(r"^#### (\w+)$", readme_section, flags=re.MULTILINE))
    assert set(names) == headings


def test_every_field_appears(tool, readme_section) -> None:
    for path in sorted((REPO_ROOT / "rosmc_msgs" / "msg").glob("*.msg")):
        section = tool.parse_section(path.read_text().splitlines(), True)
        for field in section.fields:
            assert f"| `{field.name}` |" in readme_section, f"{path.stem}.{field.name}"
        for constant in section.constants:
            if constant.name:
                assert f"| `{constant.name}` |" in readme_section, f"{path.stem}.{constant.name}"


def test_check_mode_reports_a_stale_readme(tool, tmp_path, monkeypatch) -> None:
    stale = tmp_path / "README.md"
    stale.write_text(f"# x\n\n{tool.BEGIN}\nold\n{tool.END}\n\n## After\n")
    monkeypatch.setattr(tool, "README", stale)
    assert tool.main(["--check"]) == 1
    assert tool.main(["--write"]) == 0
    assert tool.main(["--check"]) == 0
    text = stale.read_text()
    assert text.startswith("# x\n\n") and text.endswith(f"{tool.END}\n\n## After\n")
