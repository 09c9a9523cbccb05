#!/usr/bin/env bash
# A crate whose integration tests are one binary (`autotests = false`, tests/integration.rs
# declaring each file as a module) compiles only the files that binary declares: a new
# tests/*.rs left out of it would never run. Every such file is a module of integration.rs or
# a [[test]] target of its own.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo metadata --format-version 1 --no-deps | python3 -c '
import json, re, sys
from pathlib import Path
bad, crates = [], 0
for p in json.load(sys.stdin)["packages"]:
    root = Path(p["manifest_path"]).parent
    targets = {Path(t["src_path"]).resolve() for t in p["targets"] if "test" in t["kind"]}
    merged = root / "tests" / "integration.rs"
    if merged.resolve() not in targets:
        continue
    crates += 1
    declared = set(re.findall(r"^\s*mod (\w+);", merged.read_text(), re.M))
    for f in sorted((root / "tests").glob("*.rs")):
        if f.resolve() not in targets and f.stem not in declared:
            bad.append(f"{f.relative_to(root.parent.parent)}: neither a module of tests/integration.rs nor a [[test]]")
for b in bad:
    print(f"check_test_modules: {b}", file=sys.stderr)
if not bad:
    print(f"check_test_modules: {crates} crates with one integration-test binary, every file in it")
sys.exit(1 if bad else 0)
'
