# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""What the Python tests share: the KITTI sample (MSF_KITTI_DIR), the tools (MSF_BIN_DIR) and
running a tool. ctest sets both and PYTHONPATH (tests/python/CMakeLists.txt); a test whose data is
absent is skipped with a message, except under CI=true, where every test must run."""
import os
import subprocess

import pytest


def _require(path, what):
    if path and os.path.isdir(path):
        return path
    message = f"{what} not found ({path or 'unset'})"
    if os.environ.get("CI") == "true":
        pytest.fail(message + ": under CI every test must run")
    pytest.skip(message)


@pytest.fixture(scope="session")
def kitti_dir():
    return _require(os.environ.get("MSF_KITTI_DIR"), "the KITTI sample (MSF_KITTI_DIR)")


@pytest.fixture(scope="session")
def odometry04(kitti_dir):
    return _require(os.path.join(kitti_dir, "odometry", "sequences", "04"), "KITTI odometry sequence 04")


@pytest.fixture(scope="session")
def bin_dir():
    return _require(os.environ.get("MSF_BIN_DIR"), "the msf_* tools (MSF_BIN_DIR)")


@pytest.fixture(scope="session")
def run_tool(bin_dir):
    """Runs build/bin/<tool> with arguments; fails the test with its stderr when it fails."""

    def run(tool, *args):
        r = subprocess.run([os.path.join(bin_dir, tool), *map(str, args)], capture_output=True, text=True)
        assert r.returncode == 0, f"{tool} {' '.join(map(str, args))} failed: {r.stderr}"
        return r

    return run
