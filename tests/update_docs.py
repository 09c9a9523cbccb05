#!/usr/bin/env python3
"""The generated parts of docs/: each executable's parameter table.

A page holds an executable's table between two marker lines::

    <!-- BEGIN GENERATED: chassis_node --params-markdown -->
    | parameter | type | default | allowed | description |
    ...
    <!-- END GENERATED -->

The text between them is exactly what ``chassis_node --params-markdown`` prints, which the
executable builds from its one parameter declaration (the same that gives ``--help`` and
``describe_parameters``). ``tests/test_docs.py`` fails when a page differs; this script rewrites
every table from the built executables:

    cargo build --release --bins && python3 tests/update_docs.py

Executables are taken from MOBIL_BIN_DIR (default target/release).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
BIN_DIR = Path(os.environ.get("MOBIL_BIN_DIR", str(ROOT / "target" / "release")))

BLOCK = re.compile(
    r"^<!-- BEGIN GENERATED: (?P<exe>[A-Za-z0-9_]+) --params-markdown -->\n"
    r"(?P<body>.*?)"
    r"^<!-- END GENERATED -->$",
    re.S | re.M,
)


def pages() -> list[Path]:
    """Every Markdown page of docs/."""
    return sorted(DOCS.rglob("*.md"))


def blocks(text: str) -> list[re.Match]:
    """The generated blocks of a page, in order."""
    return list(BLOCK.finditer(text))


def workspace_executables() -> set[str]:
    """Every executable of the workspace, as cargo names them: each crate's [[bin]] entries, the
    files of its src/bin/ (built without an entry), and its src/main.rs under the package's name
    unless a [[bin]] entry builds that file."""
    import tomllib
    names: set[str] = set()
    for manifest in ROOT.glob("nodes/*/Cargo.toml"):
        data = tomllib.loads(manifest.read_text())
        bins = data.get("bin", [])
        names.update(b["name"] for b in bins)
        paths = {b.get("path") for b in bins}
        names.update(p.stem for p in (manifest.parent / "src" / "bin").glob("*.rs")
                     if f"src/bin/{p.name}" not in paths)
        if (manifest.parent / "src" / "main.rs").exists() and not any(
                b.get("path") == "src/main.rs" for b in bins):
            names.add(data["package"]["name"])
    return names


def generated(exe: str) -> str:
    """What the executable prints for --params-markdown."""
    path = BIN_DIR / exe
    if not path.exists():
        raise FileNotFoundError(f"{path} is not built (cargo build --release --bins)")
    out = subprocess.run([str(path), "--params-markdown"], capture_output=True, text=True,
                         timeout=30, check=True)
    return out.stdout


def block(exe: str) -> str:
    """A whole generated block, markers included."""
    return f"<!-- BEGIN GENERATED: {exe} --params-markdown -->\n{generated(exe)}<!-- END GENERATED -->"


def update() -> int:
    """Rewrites every block from its executable; returns the number of pages changed."""
    changed = 0
    for page in pages():
        text = page.read_text()
        new = BLOCK.sub(lambda m: block(m.group("exe")), text)
        if new != text:
            page.write_text(new)
            print(f"update_docs: rewrote {page.relative_to(ROOT)}")
            changed += 1
    return changed


if __name__ == "__main__":
    n = update()
    print(f"update_docs: {n} page(s) changed")
    sys.exit(0)
