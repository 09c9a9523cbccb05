"""The repository in a ROS 2 workspace: `colcon build` with the colcon extensions from PyPI
(tests/setup_env.sh pins them, in a venv of their own) builds the interface packages and the
`mobil` package (ros/mobil: cargo in the workspace's own target directory, nothing rebuilt),
and the installed tree is used as ROS tools use it: with only `install/setup.sh`'s environment,
chassis_node is started by its installed path with its installed parameter file and an rclpy
client reads its parameters; `ament_index_python` finds the package and its files; every
launch file names executables and files that are installed.

The launch files cannot be run here (no launch_ros wheel on PyPI): they are parsed, their
`$(find-pkg-share …)` resolved against the install tree.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

import harness
from harness import ROOT

# One workspace for the module, its tests on one worker; the build takes about 40 s alone
# (tests/run_all runs the module after cargo doc, which holds target/'s lock).
pytestmark = [pytest.mark.xdist_group("colcon"), pytest.mark.timeout(600)]

PY = f"{sys.version_info.major}.{sys.version_info.minor}"
COLCON = ROOT / "target" / f"colcon-venv-py{PY}" / "bin" / "colcon"
VENV = Path(sys.prefix)
PACKAGES = {"mobil", "mobil_msgs", "nav2_msgs", "bond", "tf2_msgs"}


# What a login shell has, of the test process's environment: nothing of the repository.
KEPT = ("HOME", "USER", "LANG", "LC_ALL", "TERM", "TMPDIR", "CARGO_HOME", "RUSTUP_HOME", "ROS_DOMAIN_ID")


def build_env() -> dict[str, str]:
    """A shell as a ROS user's would be after sourcing the ROS install (here: the rclpy venv,
    its bin/ first on PATH and its prefix as the ament and CMake prefix), and nothing else."""
    env = {k: os.environ[k] for k in KEPT if k in os.environ}
    system_path = [p for p in os.environ.get("PATH", "").split(os.pathsep) if str(ROOT) not in p]
    env["PATH"] = os.pathsep.join([str(VENV / "bin"), *system_path])
    env["AMENT_PREFIX_PATH"] = str(VENV)
    env["CMAKE_PREFIX_PATH"] = str(VENV)
    return env


def sourced(setup: Path, env: dict[str, str]) -> dict[str, str]:
    """The environment after `. setup` in a POSIX shell."""
    out = subprocess.run(["sh", "-c", f'. "{setup}" && env -0'], env=env, cwd=setup.parent,
                         capture_output=True, check=True, timeout=60).stdout
    return dict(line.split("=", 1) for line in out.decode().split("\0") if "=" in line)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if not COLCON.is_file():
        pytest.fail(f"{COLCON} missing: run tests/setup_env.sh")
    ws = tmp_path_factory.mktemp("colcon_ws")
    (ws / "src").mkdir()
    (ws / "src" / "mobil").symlink_to(ROOT, target_is_directory=True)
    listed = subprocess.run([str(COLCON), "list", "--names-only"], cwd=ws, env=build_env(),
                            capture_output=True, text=True, timeout=120)
    assert listed.returncode == 0, listed.stderr
    assert set(listed.stdout.split()) == PACKAGES, listed.stdout
    # The interface packages C-only (the Python clients' half, as tests/setup_env.sh builds them).
    build = subprocess.run(
        [str(COLCON), "build", "--event-handlers", "console_direct-",
         "--cmake-args", "-DBUILD_TESTING=OFF", "-DMOBIL_MSGS_C_ONLY=ON",
         f"-DPython3_EXECUTABLE={VENV / 'bin' / 'python'}"],
        cwd=ws, env=build_env(), capture_output=True, text=True, timeout=1200)
    log = ws / "colcon-build.log"
    log.write_text(build.stdout + build.stderr)
    assert build.returncode == 0, f"colcon build failed (see {log}):\n{build.stderr[-4000:]}"
    # cargo ran in the workspace's own target directory, which the suite's build had filled:
    # nothing compiled (nodes/feature_set makes the two builds' feature sets one).
    cargo_log = (ws / "log" / "latest_build" / "mobil" / "stdout_stderr.log").read_text()
    assert "Finished `release` profile" in cargo_log, cargo_log[-3000:]
    assert "Compiling" not in cargo_log, cargo_log[-3000:]
    return ws


def installed_env(ws: Path) -> dict[str, str]:
    """`install/setup.sh` on top of a shell that has only the rclpy venv (no repository paths)."""
    return sourced(ws / "install" / "setup.sh", build_env())


def test_colcon_installs_the_ament_layout(workspace: Path):
    install = workspace / "install"
    for pkg in PACKAGES:
        assert (install / pkg / "share" / "ament_index" / "resource_index" / "packages" / pkg).is_file(), pkg
        assert (install / pkg / "share" / pkg / "package.xml").is_file(), pkg
    lib = install / "mobil" / "lib" / "mobil"
    built = {p.name for p in (ROOT / "target" / "release").iterdir()
             if p.is_file() and os.access(p, os.X_OK) and not p.suffix}
    installed = {p.name for p in lib.iterdir()}
    assert {"chassis_node", "sim_node", "local_nav_node", "planner_node", "drive_node", "terrain_node",
            "gait_node", "ga_step", "gait_demo"} <= installed
    assert installed <= built, installed - built
    share = install / "mobil" / "share" / "mobil"
    assert {p.name for p in (ROOT / "params").glob("*.yaml")} <= {p.name for p in (share / "params").glob("*.yaml")}
    assert (share / "params" / "worlds" / "default.yaml").is_file()


def test_ament_index_finds_the_package_and_its_params(workspace: Path):
    env = installed_env(workspace)
    code = ("from ament_index_python.packages import get_package_share_directory as s\n"
            "import os\n"
            "d = s('mobil')\n"
            "print(d)\n"
            "print(os.path.isfile(os.path.join(d, 'params', 'omr3.yaml')))\n"
            "print(s('mobil_msgs'))\n")
    out = subprocess.run([str(VENV / "bin" / "python"), "-c", code], env=env, capture_output=True,
                         text=True, timeout=60, check=True).stdout.split()
    assert out == [str(workspace / "install" / "mobil" / "share" / "mobil"), "True",
                   str(workspace / "install" / "mobil_msgs" / "share" / "mobil_msgs")], out


def test_installed_chassis_node_with_installed_params_answers_rclpy(workspace: Path, start_node, ros_node):
    env = installed_env(workspace)
    # Only the install tree and the rclpy venv: no value names the repository otherwise.
    leaks = {k: v for k, v in env.items() if str(ROOT) in v.replace(str(VENV), "")}
    assert not leaks, leaks
    prefix = next(Path(p) for p in env["AMENT_PREFIX_PATH"].split(os.pathsep) if p.endswith("/mobil"))
    exe = prefix / "lib" / "mobil" / "chassis_node"
    params = prefix / "share" / "mobil" / "params" / "mobil2.yaml"
    assert exe.is_file() and params.is_file()
    # Run from an empty directory with exactly that environment (env -i drops what the test
    # harness adds): nothing may be found relative to the repository.
    cwd = workspace / "empty"
    cwd.mkdir(exist_ok=True)
    start_node(str(exe), params_file=params,
               prefix=("env", "-i", *(f"{k}={v}" for k, v in env.items()), "env", "-C", str(cwd)))
    assert harness.param_get(ros_node, "chassis", "model") == "car_like"
    assert harness.param_get(ros_node, "chassis", "min_turning_radius") == pytest.approx(0.73)


# ---- launch files --------------------------------------------------------------------------------

SUBST = re.compile(r"\$\(find-pkg-share ([A-Za-z0-9_]+)\)")
# ROS 2 launch's own grammar of substitutions (Jazzy's, vendored), with the lark the venv has.
GRAMMAR = ROOT / "tests" / "launch_grammar.lark"


def declared_exec_depends() -> set[str]:
    xml = ET.parse(ROOT / "ros" / "mobil" / "package.xml").getroot()
    return {e.text for e in xml.iter("exec_depend")}


def test_launch_files_name_installed_executables_and_files(workspace: Path):
    install = workspace / "install"
    launch_dir = install / "mobil" / "share" / "mobil" / "launch"
    files = sorted(launch_dir.glob("*.launch.xml"))
    assert {f.name for f in files} == {"omr3.launch.xml", "mobil2.launch.xml", "tricycle.launch.xml",
                                      "robot.launch.xml", "nav2_mobil.launch.xml"}
    outside = declared_exec_depends()
    from lark import Lark
    substitutions = Lark(GRAMMAR.read_text(), start="template")
    declared_by = {f.name: {a.get("name"): a.get("default") for a in ET.parse(f).getroot().findall("arg")}
                   for f in files}

    def resolve(text: str) -> str:
        return SUBST.sub(lambda m: str(install / m.group(1) / "share" / m.group(1)), text)

    nodes = 0
    for f in files:
        root = ET.parse(f).getroot()
        assert root.tag == "launch", f
        for node in root.iter("node"):
            pkg, exe = node.get("pkg"), node.get("exec")
            if pkg == "mobil":
                assert (install / "mobil" / "lib" / "mobil" / exe).is_file(), (f.name, exe)
                nodes += 1
            else:
                assert pkg in outside, (f.name, pkg, "not an exec_depend of ros/mobil/package.xml")
        for element in root.iter():
            for value in element.attrib.values():
                if "$(" in value:
                    substitutions.parse(value)  # raises on a malformed substitution
                for path in re.findall(r"\$\(find-pkg-share [^)]*\)[^\s\"']*", value):
                    assert Path(resolve(path)).is_file(), (f.name, path)
        # An included file gets only arguments it declares, and every one it needs (no default).
        for include in root.iter("include"):
            included = Path(resolve(include.get("file"))).name
            given = {a.get("name") for a in include.findall("arg")}
            assert given <= set(declared_by[included]), (f.name, included, given)
            needed = {name for name, default in declared_by[included].items() if default is None}
            assert needed <= given, (f.name, included, needed - given)
        # Every $(var x) names an argument the file declares.
        declared = {a.get("name") for a in root.findall("arg")}
        for element in root.iter():
            for value in element.attrib.values():
                for var in re.findall(r"\$\(var ([A-Za-z0-9_]+)\)", value):
                    assert var in declared, (f.name, var)
    assert nodes == 7  # robot.launch.xml 4, nav2_mobil.launch.xml 3


def test_launch_files_mirror_the_launch_scripts():
    # robot.launch.xml starts what launch_scripts/lib.sh's mobil_robot starts, under the same flags.
    root = ET.parse(ROOT / "ros" / "mobil" / "launch" / "robot.launch.xml").getroot()
    started = {n.get("exec"): n.get("if") for n in root.iter("node")}
    assert started == {"sim_node": "$(var sim)", "chassis_node": None, "local_nav_node": "$(var nav)",
                       "planner_node": "$(var plan)"}
    for robot in ("omr3", "mobil2", "tricycle"):
        assert (ROOT / "launch_scripts" / robot).is_file()
        text = (ROOT / "ros" / "mobil" / "launch" / f"{robot}.launch.xml").read_text()
        assert f"$(find-pkg-share mobil)/params/{robot}.yaml" in text
