"""``extends``: a library that adds robots to another instead of copying it.

An extending library names its base (``extends: mars_team.yaml``, a path from the
extending file's folder, or a package's file: ``package://PKG/PATH``, ``$(find PKG)/PATH``,
see :mod:`.package_paths`) and gives its own ``name``. Its ``models`` add new robot kinds,
or new skills to a model of the base (a model entry then holds only ``skills``); its
``agents`` add team members. It may not redefine an agent, a model's description or
lost-link policy, or a skill of the base: the base stays what it says.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..documents.documents import DocumentReader


def merge_extension(base: object, extension: Mapping[Any, Any], reader: DocumentReader) -> object:
    """The base library's data with the extension's models and agents added.

    ``base`` was checked already; ``reader`` names the extending file in errors.
    """
    body = reader.mapping(
        extension, "", required={"rosmc_library", "name", "extends"}, optional={"models", "agents"}
    )
    assert isinstance(base, Mapping)
    if body["rosmc_library"] != base["rosmc_library"]:
        reader.fail("rosmc_library", f"differs from its base's ({base['rosmc_library']!r})")
    base_models: dict[str, dict[str, Any]] = {n: dict(m) for n, m in base["models"].items()}
    models: dict[str, object] = dict(base_models)
    for name, model in reader.mapping(body.get("models", {}), "models").items():
        models[name] = _merged_model(reader, base_models.get(name), model, f"models.{name}")
    agents = dict(base["agents"])
    for name, agent in reader.mapping(body.get("agents", {}), "agents").items():
        if name in agents:
            reader.fail(f"agents.{name}", "is an agent of the base library already")
        agents[name] = agent
    return {**base, "name": body["name"], "models": models, "agents": agents}


def _merged_model(
    reader: DocumentReader, base: dict[str, Any] | None, raw: object, key: str
) -> object:
    """A new model as given, or a base model with the extension's skills added."""
    if base is None:
        return raw
    body = reader.mapping(raw, key)
    others = sorted(str(name) for name in body if name != "skills")
    if others:
        reader.fail(key, f"is a model of the base: add skills to it, not {', '.join(others)}")
    skills = dict(base["skills"])
    for name, skill in reader.mapping(body.get("skills", {}), f"{key}.skills").items():
        if name in skills:
            reader.fail(f"{key}.skills.{name}", "is a skill of the base library already")
        skills[name] = skill
    return {**base, "skills": skills}
