# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The Python example of docs/python.md runs as written (the KITTI sample's path made the test's)."""
import os
import re
import subprocess
import sys


def readme_block(name):
    root = os.environ.get("MSF_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
    text = open(os.path.join(root, "docs", "python.md")).read()
    block = re.search(rf"<!-- example:{name}:begin -->\s*```python\n(.*?)```\s*<!-- example:{name}:end -->", text, re.S)
    assert block, f"docs/python.md has no python block example:{name}"
    return block.group(1)


def test_readme_python_example_runs(kitti_dir, tmp_path):
    code = readme_block("python")
    assert "../shared/data/kitti" in code
    code = code.replace("../shared/data/kitti", kitti_dir)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    drive, one_frame = [int(n) for n in re.findall(r"^(\d+) triangles", r.stdout, re.M)]
    assert drive > 100000 and 10000 < one_frame < drive
