#!/usr/bin/env python3
"""The vendored crates as published crate + patch series.

`patches/rustdds` and `patches/ros2-client` are the published crates with the changes that
patches/README.md describes. Each change is also a patch in `patches/series/<crate>/NNNN-*.patch`
against the published crate (less the files listed in `patches/series/<crate>/EXCLUDED`, which
are not vendored), so that moving to a new version is applying the series to it.

    patches/series.py check [--vendored-root DIR]   every vendored tree == published + series
    patches/series.py diff CRATE                     the vendored tree's changes not yet in the
                                                     series, as a patch (to become the next one)

The published crates are downloaded from crates.io once into target/crates/ (or taken from
cargo's cache) and checked against the SHA-256 below. `check` exits 1 naming every file that
differs, 0 when all agree.
"""
from __future__ import annotations

import argparse
import hashlib
import shutil
import subprocess
import sys
import tarfile
import tempfile
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SERIES = ROOT / "patches" / "series"
CACHE = ROOT / "target" / "crates"

# name -> (version, SHA-256 of the .crate as crates.io serves it)
CRATES = {
    "rustdds": ("0.15.1", "42683a88b9dc025d7d45771b88d20846443b4901ec4b045ca78b8dd316ab616f"),
    "ros2-client": ("0.12.1", "1fe08f96d441e37bffbfa487f3feebbdc5952ee6db2edc7861592913328f7031"),
}


def crate_file(name: str) -> Path:
    """The published .crate, verified; downloaded into target/crates/ if not there yet."""
    version, sha = CRATES[name]
    file = f"{name}-{version}.crate"
    path = CACHE / file
    if not path.is_file():
        CACHE.mkdir(parents=True, exist_ok=True)
        cached = sorted(Path.home().glob(f".cargo/registry/cache/*/{file}"))
        if cached:
            shutil.copyfile(cached[0], path)
        else:
            url = f"https://static.crates.io/crates/{name}/{file}"
            try:
                with urllib.request.urlopen(url, timeout=60) as response:
                    path.write_bytes(response.read())
            except OSError as e:
                raise SystemExit(f"series: cannot download {url} ({e}); put {file} in {CACHE} "
                                 "to check offline") from e
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != sha:
        path.unlink()
        raise SystemExit(f"series: {file} has SHA-256 {digest}, not {sha}: removed, try again")
    return path


def excluded(name: str) -> list[str]:
    lines = (SERIES / name / "EXCLUDED").read_text().splitlines()
    return [line.strip() for line in lines if line.strip() and not line.startswith("#")]


def patches(name: str) -> list[Path]:
    return sorted((SERIES / name).glob("*.patch"))


def published_plus_series(name: str, into: Path) -> Path:
    """Extracts the published crate into ``into``, drops the excluded files and applies the
    series in order; returns the crate's directory."""
    version, _ = CRATES[name]
    with tarfile.open(crate_file(name)) as tar:
        if hasattr(tarfile, "data_filter"):  # Python 3.11.4 and later
            tar.extractall(into, filter="data")
        else:
            tar.extractall(into)  # noqa: S202 - a crate of pinned SHA-256
    tree = into / f"{name}-{version}"
    for rel in excluded(name):
        target = tree / rel
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()
        else:
            raise SystemExit(f"series: {name}/EXCLUDED names {rel}, which the published crate lacks")
    for patch in patches(name):
        done = subprocess.run(["git", "apply", "--whitespace=nowarn", str(patch)], cwd=tree,
                              capture_output=True, text=True)
        if done.returncode != 0:
            raise SystemExit(f"series: {patch.relative_to(ROOT)} does not apply:\n{done.stderr}")
    return tree


def vendored_files(tree: Path) -> set[str]:
    """The vendored tree's files, as git sees them (tracked, or new and not ignored)."""
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "."], cwd=tree,
                         capture_output=True, text=True)
    if out.returncode == 0:
        return {line for line in out.stdout.splitlines() if (tree / line).is_file()}
    # Not in a git work tree: every file but build output.
    return {str(p.relative_to(tree)) for p in tree.rglob("*")
            if p.is_file() and "target" not in p.relative_to(tree).parts[:1]}


def all_files(tree: Path) -> set[str]:
    """Every file under ``tree``, but a git repository's own (``.git/``)."""
    return {str(p.relative_to(tree)) for p in tree.rglob("*")
            if p.is_file() and p.relative_to(tree).parts[0] != ".git"}


def check(vendored_root: Path) -> int:
    bad = 0
    for name in CRATES:
        with tempfile.TemporaryDirectory() as tmp:
            expected = published_plus_series(name, Path(tmp))
            vendored = vendored_root / name
            want, have = all_files(expected), vendored_files(vendored)
            problems = [f"only in the vendored tree: {f}" for f in sorted(have - want)]
            problems += [f"missing from the vendored tree: {f}" for f in sorted(want - have)]
            problems += [f"differs: {f}" for f in sorted(want & have)
                         if (expected / f).read_bytes() != (vendored / f).read_bytes()]
            n = len(patches(name))
            if problems:
                bad += 1
                print(f"series: patches/{name} is not {name} {CRATES[name][0]} + its {n} patches:")
                for p in problems:
                    print(f"  {p}")
                print(f"  (patches/series.py diff {name} shows the change a new patch must hold)")
            else:
                print(f"series: patches/{name} == {name} {CRATES[name][0]} + {n} patches")
    return 1 if bad else 0


def diff(name: str) -> int:
    with tempfile.TemporaryDirectory() as tmp:
        expected = published_plus_series(name, Path(tmp))
        vendored = ROOT / "patches" / name
        git = ["git", "-c", "user.name=series", "-c", "user.email=series@localhost"]
        subprocess.run(git + ["init", "-q"], cwd=expected, check=True)
        subprocess.run(git + ["add", "-A"], cwd=expected, check=True)
        subprocess.run(git + ["commit", "-qm", "published + series"], cwd=expected, check=True)
        for f in all_files(expected) - vendored_files(vendored):
            (expected / f).unlink()
        for f in vendored_files(vendored):
            (expected / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(vendored / f, expected / f)
        subprocess.run(git + ["add", "-A"], cwd=expected, check=True)
        out = subprocess.run(git + ["diff", "--cached", "--no-color"], cwd=expected,
                             capture_output=True, text=True, check=True)
        sys.stdout.write(out.stdout)
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    c = sub.add_parser("check", help="every vendored tree is its published crate + its series")
    c.add_argument("--vendored-root", type=Path, default=ROOT / "patches",
                   help="the directory holding the vendored crates (default: patches/)")
    d = sub.add_parser("diff", help="the vendored crate's changes not in its series yet")
    d.add_argument("crate", choices=sorted(CRATES))
    args = ap.parse_args()
    if args.command == "check":
        return check(args.vendored_root)
    return diff(args.crate)


if __name__ == "__main__":
    sys.exit(main())
