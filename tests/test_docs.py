"""The documentation against the code: every executable's parameter table in docs/ equals what
the executable prints from its declaration (``--params-markdown``), every executable has one, and
every relative link of README.md, CHANGELOG.md and docs/ resolves (file and heading).

A failing table is rewritten by ``python3 tests/update_docs.py`` (see there).
"""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path

import pytest

import update_docs as ud

ROOT = ud.ROOT
README_MAX_LINES = 300


def all_blocks() -> list[tuple[Path, str, str]]:
    """(page, executable, table on the page) for every generated block of docs/."""
    found = []
    for page in ud.pages():
        for m in ud.blocks(page.read_text()):
            found.append((page, m.group("exe"), m.group("body")))
    return found


def test_every_executable_has_exactly_one_table():
    documented = [exe for _, exe, _ in all_blocks()]
    twice = sorted({e for e in documented if documented.count(e) > 1})
    assert not twice, f"executables with more than one table in docs/: {twice}"
    assert set(documented) == ud.workspace_executables(), (
        f"missing: {sorted(ud.workspace_executables() - set(documented))}, "
        f"not an executable: {sorted(set(documented) - ud.workspace_executables())}")


@pytest.mark.parametrize("page,exe,table", all_blocks(),
                         ids=lambda v: v.name if isinstance(v, Path) else None)
def test_a_pages_table_is_the_declaration(page, exe, table):
    want = ud.generated(exe)
    assert table == want, (
        f"{page.relative_to(ROOT)}: the table of {exe} differs from `{exe} --params-markdown`; "
        f"run `python3 tests/update_docs.py` (with the executables built)")


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, only letters, digits, spaces, hyphens and
    underscores kept, spaces as hyphens."""
    kept = "".join(c for c in heading.strip().lower()
                   if c in " -_" or unicodedata.category(c)[0] in "LN")
    return kept.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
    return {slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.*?)\s*$", text, re.M)}


LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def linked_pages() -> list[Path]:
    return [ROOT / "README.md", ROOT / "CHANGELOG.md", *ud.pages()]


@pytest.mark.parametrize("page", linked_pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves(page):
    text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
    broken = []
    for target in LINK.findall(text):
        if re.match(r"[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        if not dest.exists():
            broken.append(f"{target} (no such file)")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            broken.append(f"{target} (no such heading)")
    assert not broken, f"{page.relative_to(ROOT)}: {broken}"


def test_the_readme_is_short():
    lines = (ROOT / "README.md").read_text().count("\n")
    assert lines <= README_MAX_LINES, f"README.md has {lines} lines (at most {README_MAX_LINES})"


def test_slugs_follow_github():
    assert slug("Running a robot") == "running-a-robot"
    assert slug("`planner_node`: docking") == "planner_node-docking"
    assert slug("Where the suite differs from rclcpp, and why") == "where-the-suite-differs-from-rclcpp-and-why"
    assert slug("VFO (SPEC §5)") == "vfo-spec-5"
