"""The docs' links lead somewhere: every relative link names a file, every #anchor a heading.

Covers README.md, CONTRIBUTING.md and docs/*.md. Anchors are made from headings as GitHub
makes them (lower case, punctuation dropped, spaces to hyphens). Every repository path the
docs name in backticks (``rosmc_server/core/rules/mission.py``) exists too.
"""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DOCS = [REPO / "README.md", REPO / "CONTRIBUTING.md", *sorted((REPO / "docs").glob("*.md"))]
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*```")
REPO_PATH = re.compile(
    r"`((?:rosmc_\w+|tests|test|tools|bench|launch|rviz|scripts|docs|bags)/[\w./-]*)`"
)


def prose(text: str) -> str:
    """``text`` without its fenced code blocks."""
    kept, inside = [], False
    for line in text.splitlines():
        if FENCE.match(line):
            inside = not inside
            continue
        if not inside:
            kept.append(line)
    return "\n".join(kept)


def anchor(heading: str) -> str:
    """The anchor GitHub gives a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower().replace("`", ""))
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    return {
        anchor(match.group(1))
        for match in re.finditer(r"^#{1,6} (.+)$", prose(path.read_text()), flags=re.MULTILINE)
    }


def broken_links(path: Path) -> list[str]:
    """One line per link of ``path`` that leads nowhere."""
    problems = []
    text = prose(path.read_text())
    for target in LINK.findall(text) + IMAGE.findall(text):
        if re.match(r"[a-z]+:", target):
            continue  # another site
        file_part, _, fragment = target.partition("#")
        file = (path.parent / file_part).resolve() if file_part else path
        if not file.exists():
            problems.append(f"{path.name}: {target} (no such file)")
            continue
        if fragment and file.suffix == ".md" and fragment not in anchors(file):
            problems.append(f"{path.name}: {target} (no heading makes #{fragment})")
    return problems


def test_anchors_are_made_as_github_makes_them() -> None:
    assert anchor("Every figure, one run (`make bench`)") == "every-figure-one-run-make-bench"
    assert anchor("Robots on other machines") == "robots-on-other-machines"
    assert anchor("`/rosmc/mission_server`") == "rosmcmission_server"


def test_every_link_of_the_docs_leads_somewhere() -> None:
    problems = [problem for path in DOCS for problem in broken_links(path)]
    assert not problems, "\n".join(problems)


def test_every_path_the_docs_name_exists() -> None:
    missing = [
        f"{path.name}: {name}"
        for path in DOCS
        for name in REPO_PATH.findall(path.read_text())
        if "YYYY" not in name and not (REPO / name).exists()  # a placeholder file name
    ]
    assert not missing, "\n".join(missing)


def test_a_broken_link_is_found(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("# Title\n\n[ok](#title) [gone](#nothing) [file](missing.md)\n")
    assert broken_links(page) == [
        "page.md: #nothing (no heading makes #nothing)",
        "page.md: missing.md (no such file)",
    ]


def test_the_readme_is_a_front_page() -> None:
    readme = (REPO / "README.md").read_text()
    assert len(readme.splitlines()) <= 300
    assert readme.startswith("# ROSMC")
    for page in ("operator-guide", "integrator-guide", "replay", "reference", "performance"):
        assert f"(docs/{page}.md)" in readme, page
    assert "(docs/glossary.md)" in readme and "(docs/architecture.md)" in readme
