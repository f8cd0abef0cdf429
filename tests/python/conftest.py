"""Fixtures for the Python module's tests (run by ctest: tests/CMakeLists.txt sets DYNBENCH_EXE
to the dynbench executable of the same build and PYTHONPATH to its python/ folder)."""
import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ORBIT = ROOT / "examples" / "orbit" / "orbit.gltf"


def dynbench_exe():
    exe = os.environ.get("DYNBENCH_EXE")
    if not exe:
        pytest.fail("DYNBENCH_EXE is not set (ctest sets it; see tests/CMakeLists.txt)")
    return exe


def run_cli(*args, check=True):
    """The dynbench executable with args; its completed process."""
    result = subprocess.run([dynbench_exe(), *map(str, args)], capture_output=True, text=True)
    if check and result.returncode != 0:
        raise AssertionError(f"dynbench {' '.join(map(str, args))}: status {result.returncode}\n{result.stderr}")
    return result


def cli_json(tmp_path, *args):
    """What the CLI writes with --json for these args, read back as json.load reads it."""
    out = tmp_path / f"cli_{len(list(tmp_path.iterdir()))}.json"
    run_cli(*args, "--json", out)
    return json.loads(out.read_text())


@pytest.fixture(scope="session")
def frames(tmp_path_factory):
    """Six frames of the orbit example rendered twice: as a real-time renderer's input (4 paths per
    pixel from the jittered centre, with motion) and as the reference (256 paths)."""
    root = tmp_path_factory.mktemp("frames")
    common = [ORBIT, "--res", "40x24", "--frames", "0:5", "--bounces", "2"]
    run_cli("render", *common, "-o", root / "input", "--spp", "4", "--jitter", "--pixel-filter", "centre")
    run_cli("render", *common, "-o", root / "reference", "--spp", "256", "--pairs", "--max-pairs", "16")  # discard's default test reads pairs
    return {"input": root / "input", "reference": root / "reference"}
