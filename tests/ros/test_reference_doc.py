"""docs/reference.md's generated part matches rosmc_msgs/ and the node modules.

Regenerate with ``python tools/gen_msg_reference.py --write``.
"""

from __future__ import annotations

import ast
import importlib.util
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
TOOLS = REPO_ROOT / "tools"
TOOL = TOOLS / "gen_msg_reference.py"
DOC = REPO_ROOT / "docs" / "reference.md"


@pytest.fixture(scope="module")
def tool() -> Iterator[ModuleType]:
    spec = importlib.util.spec_from_file_location("gen_msg_reference", TOOL)
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    sys.path.insert(0, str(TOOLS))  # the tool imports its sibling, as when run as a script
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.path.remove(str(TOOLS))
        del sys.modules[spec.name]


@pytest.fixture(scope="module")
def generated(tool: ModuleType) -> str:
    text = DOC.read_text()
    start, end = text.index(tool.BEGIN), text.index(tool.END)
    return text[start : end + len(tool.END)] + "\n"


def test_reference_is_generated_from_the_definitions(tool, generated) -> None:
    assert generated == tool.generate(), (
        "docs/reference.md is out of date: python tools/gen_msg_reference.py --write"
    )


def test_every_definition_has_a_section(generated) -> None:
    names = [p.stem for p in sorted((REPO_ROOT / "rosmc_msgs").glob("*/*.[ms][sr][gv]"))]
    assert len(names) >= 40
    headings = set(re.findall(r"^### (\w+)$", generated, flags=re.MULTILINE))
    assert set(names) == headings


def test_every_field_appears(tool, generated) -> None:
    for path in sorted((REPO_ROOT / "rosmc_msgs" / "msg").glob("*.msg")):
        section = tool.parse_section(path.read_text().splitlines(), True)
        for field in section.fields:
            assert f"| `{field.name}` |" in generated, f"{path.stem}.{field.name}"
        for constant in section.constants:
            if constant.name:
                assert f"| `{constant.name}` |" in generated, f"{path.stem}.{constant.name}"


def _private_params_read(path: Path) -> set[str]:
    """Literal ``get_param("~name", ...)`` names of a module, found independently of the tool."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call) and getattr(node.func, "attr", "") == "get_param":
            first = node.args[0] if node.args else None
            if isinstance(first, ast.Constant) and str(first.value).startswith("~"):
                names.add(first.value)
    return names


def test_every_node_parameter_is_listed_and_described(tool, generated) -> None:
    nodes = sys.modules["node_params_reference"].node_parameters()
    assert {node for node, _module, _params in nodes} >= {
        "/rosmc/mission_server",
        "/<robot>/mission_executor",
        "/rosmc/sim",
        "/rosmc/markers",
    }
    for node, module, params in nodes:
        listed = {param.name for param in params}
        assert _private_params_read(REPO_ROOT / module) <= listed, node
        for param in params:
            assert param.description, f"{module}'s docstring does not describe {param.name}"
            assert f"| `{param.name}` |" in generated
    markers = next(params for node, _m, params in nodes if node == "/rosmc/markers")
    # names held in constants (rosmc_rviz_markers/topics.py) are resolved too
    assert {"~ns", "~read_only", "~follow_tf", "~commit_delay"} <= {p.name for p in markers}


def test_check_mode_reports_a_stale_document(tool, tmp_path, monkeypatch) -> None:
    stale = tmp_path / "reference.md"
    stale.write_text(f"# x\n\n{tool.BEGIN}\nold\n{tool.END}\n\n## After\n")
    monkeypatch.setattr(tool, "DOC", stale)
    assert tool.main(["--check"]) == 1
    assert tool.main(["--write"]) == 0
    assert tool.main(["--check"]) == 0
    text = stale.read_text()
    assert text.startswith("# x\n\n") and text.endswith(f"{tool.END}\n\n## After\n")


def test_every_request_field_of_a_service_says_what_it_means(generated) -> None:
    # rosservice call users read the default of each field they leave out here.
    services = generated[generated.index("## Service definitions") :]
    blank = []
    for block in services.split("\n### ")[1:]:
        name = block.split("\n", 1)[0]
        request = block.split("Request:")[1].split("Response:")[0] if "Request:" in block else ""
        blank += [
            f"{name}.{row.split('|')[1].strip()}"
            for row in request.splitlines()
            if row.startswith("| `")
            and row.rstrip().endswith("|  |")
            and row.count("|") == 4  # a field (a constant's row has its value too)
        ]
    assert blank == [], "give these fields a comment in rosmc_msgs/srv"


def test_an_indented_comment_line_goes_on_with_the_field_above(tool) -> None:
    section = tool.parse_section(
        [
            'string policy   # in force; "" = as last said',
            "                # (repeated only now and then)",
            "# said of the field below",
            "float64 echo    # echoed",
        ],
        leading_description=False,
    )
    assert [(f.name, f.comment) for f in section.fields] == [
        ("policy", 'in force; "" = as last said (repeated only now and then)'),
        ("echo", "said of the field below echoed"),
    ]
