"""Fixtures: the vmap CLI and the module built beside it, and a map of a short stretch of lab_floor built by each.

ctest sets VMAP_CLI (build/vmap), VMAP_SHARED_DIR and PYTHONPATH (build/python). Without ../shared the tests
that need its data are skipped.
"""
import json
import os
import pathlib
import subprocess

import pytest

import vmap

SHARED = pathlib.Path(os.environ.get("VMAP_SHARED_DIR", pathlib.Path(__file__).parents[3] / "shared"))
VIDEO = SHARED / "data" / "lab_floor" / "lab_floor.mp4"
CLI = os.environ.get("VMAP_CLI", str(pathlib.Path(__file__).parents[2] / "build" / "vmap"))
# A short stretch: 60 frames, every second one.
STRETCH = {"first": 0, "last": 59, "stride": 2}
# The module's logs and progress off, as the CLI's with -q.
vmap.set_log_level("quiet")


def run_cli(*args):
    """Runs the vmap CLI; returns its stdout, or fails the test with its stderr."""
    done = subprocess.run([CLI, *map(str, args), "-q"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout


def needs_shared():
    if not VIDEO.is_file():
        pytest.skip(f"{VIDEO} not found (../shared is not there)")
    if not os.access(CLI, os.X_OK):
        pytest.skip(f"the vmap CLI {CLI} is not built")


@pytest.fixture(scope="session")
def maps(tmp_path_factory):
    """The same map built by `vmap build` and by vmap.build_map: (cli_dir, module_dir, module's Map)."""
    needs_shared()
    root = tmp_path_factory.mktemp("maps")
    cli_dir, module_dir = root / "cli_map", root / "module_map"
    run_cli("build", VIDEO, "-o", cli_dir, *[f"--{k}={v}" for k, v in STRETCH.items()])
    built = vmap.build_map(str(VIDEO), module_dir, **STRETCH)
    return cli_dir, module_dir, built


def map_json(directory):
    with open(pathlib.Path(directory) / "map.json") as f:
        return json.load(f)
