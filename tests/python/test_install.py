# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""make install puts the package where Debian's python3 finds it: PREFIX/lib/python3.X/dist-packages,
which is on python3's path for the default prefix /usr/local."""
import glob
import os
import subprocess
import sys

import pytest


@pytest.fixture(scope="module")
def build_dir():
    path = os.environ.get("MSF_BUILD_DIR")
    if not path or not os.path.isfile(os.path.join(path, "CMakeCache.txt")):
        pytest.skip("the build folder (MSF_BUILD_DIR) is unknown: run through ctest")
    return path


def test_installed_package_is_importable_on_debians_path(build_dir, tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build_dir, "--component", "python", "--prefix", str(prefix)], check=True,
                   capture_output=True)
    [init] = glob.glob(str(prefix / "**" / "msfusion" / "__init__.py"), recursive=True)
    site = os.path.dirname(os.path.dirname(init))
    relative = os.path.relpath(site, prefix)
    assert glob.glob(os.path.join(site, "msfusion", "_core*.so"))
    assert os.path.join("/usr/local", relative) in sys.path, f"{relative} under /usr/local is not on {sys.path}"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = site  # stands for /usr/local's folder, which python3 reads without it
    r = subprocess.run([sys.executable, "-c", "import msfusion; print(msfusion.__file__, msfusion.Config().voxel_size)"],
                       capture_output=True, text=True, env=env, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == [init, "0.1"]
