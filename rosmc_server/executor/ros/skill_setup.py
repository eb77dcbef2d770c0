"""The robot's skills at executor start: its implementations fitted to its library.

The library (``~library``, else the skills module's ``library(agent)`` if it has one)
declares each skill's parameters and may bind skills to ROS actions, services or topics;
the skills module (``~skills``) implements the rest in code. :func:`robot_skill_types`
checks one against the other and refuses to start on a mismatch. Without a library the
implementations run as they are, their parameters unchecked by the robot.
"""

from __future__ import annotations

import importlib
import logging
from collections.abc import Mapping
from pathlib import Path

from rosmc_server.core import load_library

from ..core import SkillType
from ..core.fitting import fit_to_library
from .bindings import bound_skill_type

_log = logging.getLogger(__name__)


def default_library(skills: str, agent: str) -> str:
    """The skills module's own library for ``agent`` ("" if it names none)."""
    module = importlib.import_module(skills.partition(":")[0])
    factory = getattr(module, "library", None)
    return "" if factory is None else str(factory(agent))


def robot_skill_types(
    agent: str, implementations: Mapping[str, SkillType], library: Path | None
) -> dict[str, SkillType]:
    """What ``agent`` runs; LibraryError or SkillSetupError (one sentence) if it cannot."""
    if library is None:
        return dict(implementations)
    fitted = fit_to_library(load_library(library), agent, implementations, bound_skill_type)
    if fitted.unimplemented:
        _log.warning(
            "%s: nothing implements %s of library %s: uploads of them are refused",
            agent,
            ", ".join(fitted.unimplemented),
            library,
        )
    if fitted.unlisted:
        _log.info("%s: %s not in the library's model: never run", agent, ", ".join(fitted.unlisted))
    return fitted.types
