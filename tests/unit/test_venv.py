"""rosmc_server.venv: where entry scripts look for the project's PyPI packages."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from rosmc_server import venv


def test_rosmc_venv_comes_first_then_the_checkouts_venv(tmp_path: Path) -> None:
    found = venv.candidate_venvs({"ROSMC_VENV": str(tmp_path / "mine")})
    assert found[0] == tmp_path / "mine"
    checkout = Path(venv.__file__).resolve().parents[1]
    assert checkout / ".venv" in found[1:]


def test_site_packages_goes_before_debians_packages(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    packages = venv.site_packages(tmp_path)
    packages.mkdir(parents=True)
    path = ["/usr/lib/python3.11", "/usr/lib/python3/dist-packages", "/opt/ros/lib"]
    monkeypatch.setattr(sys, "path", path)
    monkeypatch.setattr(sys, "prefix", sys.base_prefix)  # as /usr/bin/python3 runs a relay

    assert venv.use_project_venv({"ROSMC_VENV": str(tmp_path)}) == tmp_path
    assert path[1] == str(packages)
    assert venv.use_project_venv({"ROSMC_VENV": str(tmp_path)}) == tmp_path
    assert path.count(str(packages)) == 1, "a second call adds nothing"


def test_nothing_changes_inside_a_venv_or_without_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = ["/usr/lib/python3/dist-packages"]
    monkeypatch.setattr(sys, "path", path)
    monkeypatch.setattr(sys, "prefix", "/somewhere/else")
    venv.site_packages(tmp_path).mkdir(parents=True)
    assert venv.use_project_venv({"ROSMC_VENV": str(tmp_path)}) is None

    monkeypatch.setattr(sys, "prefix", sys.base_prefix)
    monkeypatch.setattr(venv, "_package_path", lambda: [str(tmp_path / "nowhere" / "pkg")])
    assert venv.use_project_venv({}) is None
    assert path == ["/usr/lib/python3/dist-packages"]


def _entry_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str, body: str) -> str:
    """A module ``name`` in ``tmp_path`` (on sys.path) whose text is ``body``."""
    (tmp_path / f"{name}.py").write_text(body)
    monkeypatch.syspath_prepend(str(tmp_path))
    return name


def test_an_entry_point_runs_main_and_returns_its_status(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    module = _entry_module(tmp_path, monkeypatch, "entry_ok", "def main():\n    return 3\n")
    assert venv.run_entry_point(module) == 3


def test_ctrl_c_while_the_program_imports_ends_it_quietly_with_130(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    body = "raise KeyboardInterrupt  # as if Ctrl-C came during the imports\n"
    module = _entry_module(tmp_path, monkeypatch, "entry_interrupted", body)
    assert venv.run_entry_point(module) == 130
    assert capsys.readouterr().err == "", "no traceback"


def test_a_missing_dependency_ends_in_one_sentence_naming_both_routes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    body = "import mcap_ros1.decoder\n\ndef main():\n    return 0\n"
    monkeypatch.setitem(sys.modules, "mcap_ros1", None)  # as if it were not installed
    monkeypatch.setattr(sys, "argv", ["/opt/ws/install/lib/rosmc/rosmc", "--help"])
    module = _entry_module(tmp_path, monkeypatch, "entry_needs_mcap", body)

    assert venv.run_entry_point(module) == 1
    error = capsys.readouterr().err
    assert error.startswith("rosmc: the Python module 'mcap_ros1' (PyPI package mcap-ros1-support)")
    assert "rosdep install --from-paths src --ignore-src -y" in error
    assert "ROSMC_VENV" in error
    assert error.count(". ") == 0 and error.count("\n") == 1, "one sentence, one line"


def test_a_missing_module_of_the_project_itself_is_not_hidden(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    module = _entry_module(tmp_path, monkeypatch, "entry_broken", "import rosmc_not_here\n")
    with pytest.raises(ModuleNotFoundError, match="rosmc_not_here"):
        venv.run_entry_point(module)


def test_an_unused_optional_module_is_kept_out_of_the_program(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # As genpy does with numpy: an optional import, handled when it fails.
    (tmp_path / "entry_optional_extra.py").write_text("LOADED = True\n", encoding="utf-8")
    body = (
        "try:\n    import entry_optional_extra\n"
        "except ImportError:\n    entry_optional_extra = None\n"
        "\ndef main():\n    return 0 if entry_optional_extra is None else 5\n"
    )
    try:
        module = _entry_module(tmp_path, monkeypatch, "entry_lean", body)
        assert venv.run_entry_point(module, unused=("entry_optional_extra",)) == 0
        sys.modules.pop(module)
        sys.modules.pop("entry_optional_extra")
        assert venv.run_entry_point(module) == 5  # installed and not kept out: imported
    finally:
        sys.modules.pop("entry_optional_extra", None)


def test_a_deferred_module_is_imported_when_its_function_is_first_called(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "entry_costly.py").write_text(
        "IMPORTS = []\nIMPORTS.append(1)\n\ndef twice(value, factor=2):\n"
        "    return (value * factor, len(IMPORTS))\n",
        encoding="utf-8",
    )
    body = (
        "import sys\nfrom entry_costly import twice\n\ndef main():\n"
        "    assert sys.modules['entry_costly'].__doc__.startswith('Stands in')\n"
        "    assert twice(3) == (6, 1) and twice(2, factor=5) == (10, 1)\n"
        "    return 0 if sys.modules['entry_costly'].__doc__ is None else 4  # the real one\n"
    )
    try:
        module = _entry_module(tmp_path, monkeypatch, "entry_deferring", body)
        assert venv.run_entry_point(module, deferred={"entry_costly": ("twice",)}) == 0
    finally:
        sys.modules.pop("entry_costly", None)
