"""``rosmc_command``'s start: an optional import hidden while the window's modules load."""

from __future__ import annotations

import importlib
import sys

import pytest

from rosmc_rqt_command.start import hidden


def test_a_hidden_module_fails_to_import_inside_the_block_only(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delitem(sys.modules, "tabnanny", raising=False)
    with hidden("tabnanny"), pytest.raises(ImportError):
        importlib.import_module("tabnanny")
    assert "tabnanny" not in sys.modules
    assert importlib.import_module("tabnanny").__name__ == "tabnanny"


def test_a_module_imported_already_stays_usable() -> None:
    with hidden("json"):
        assert importlib.import_module("json") is sys.modules["json"]
    assert sys.modules["json"] is not None
