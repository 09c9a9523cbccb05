"""The vendored crates are their published versions plus the patch series (patches/series.py):
the check passes on the repository and fails, naming the file, when a vendored file is edited
without a patch for it."""

from __future__ import annotations

import shutil
import subprocess
import sys

from harness import ROOT

SERIES = [sys.executable, str(ROOT / "patches" / "series.py")]


def test_the_vendored_crates_are_published_plus_series():
    done = subprocess.run(SERIES + ["check"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "rustdds == rustdds 0.15.1 +" in done.stdout
    assert "ros2-client == ros2-client 0.12.1 +" in done.stdout


def test_an_edit_without_its_patch_fails_the_check(tmp_path):
    # A copy of the vendored trees (the files git has), one file changed by a comment.
    for crate in ("rustdds", "ros2-client"):
        files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "."],
                               cwd=ROOT / "patches" / crate, capture_output=True, text=True,
                               check=True).stdout.split()
        for f in files:
            dest = tmp_path / crate / f
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(ROOT / "patches" / crate / f, dest)
    clean = subprocess.run(SERIES + ["check", "--vendored-root", str(tmp_path)],
                           capture_output=True, text=True, timeout=120)
    assert clean.returncode == 0, clean.stdout + clean.stderr
    lib = tmp_path / "rustdds" / "src" / "lib.rs"
    lib.write_text(lib.read_text() + "\n// an edit without a patch\n")
    edited = subprocess.run(SERIES + ["check", "--vendored-root", str(tmp_path)],
                            capture_output=True, text=True, timeout=120)
    assert edited.returncode == 1, edited.stdout + edited.stderr
    assert "differs: src/lib.rs" in edited.stdout
    assert "ros2-client == ros2-client 0.12.1 +" in edited.stdout
