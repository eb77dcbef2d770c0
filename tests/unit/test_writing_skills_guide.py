"""docs/writing-skills.md: its libraries load and its example module fits its library."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from rosmc_server.core import load_library
from rosmc_server.executor.core import SkillType
from rosmc_server.executor.core.fitting import fit_to_library
from tests.guide_blocks import blocks, write_files


def test_every_library_in_the_guide_loads(tmp_path: Path) -> None:
    files = write_files(tmp_path)
    libraries = [
        files[name] for name in files if name.endswith(".yaml") and name != "mars_team.yaml"
    ]
    assert len(libraries) == len(blocks("yaml")) == 2
    names = {load_library(path).name for path in libraries}
    assert names == {"mars_lab", "sweeper_lab"}
    lab = load_library(files["mars_lab.yaml"])
    assert {"go_to", "lamp", "look_at"} <= set(lab.skills_of("lab_rover"))
    assert "take_spectrum" in lab.skills_of("science_rover")


def test_the_example_module_fits_the_example_library(tmp_path: Path) -> None:
    files = write_files(tmp_path)
    spec = importlib.util.spec_from_file_location("lab_skills", files["lab_skills.py"])
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    types: list[SkillType] = module.skill_types("sweeper1")

    def no_binding(_: object) -> SkillType:
        raise AssertionError("the example binds nothing")

    library = load_library(files["sweeper_lab.yaml"])
    fitted = fit_to_library(library, "sweeper1", {t.name: t for t in types}, no_binding)
    assert sorted(fitted.types) == ["sweep"] and fitted.unimplemented == ()
