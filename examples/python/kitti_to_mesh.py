# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""A KITTI drive to a coloured mesh:
PYTHONPATH=build/python /usr/bin/python3 examples/python/kitti_to_mesh.py SEQUENCE_DIR MESH.ply [FRAMES]
(from the repository, with the build tree's module; see docs/python.md)"""
import itertools
import sys

import msfusion

if len(sys.argv) < 3:
    sys.exit(__doc__)  # the usage

sequence = msfusion.Sequence(sys.argv[1])              # KITTI odometry sequence, raw drive or msf_synth's street
engine = msfusion.Reconstructor(sequence.calibration)  # every stage with config/kitti.yaml's settings
for frame in itertools.islice(sequence, int(sys.argv[3]) if len(sys.argv) > 3 else None):
    result = engine.add_frame(frame)                   # fused depth and weight, integrated at the frame's pose
    print(f"frame {frame.name}: {(result.depth > 0).mean():.0%} of the pixels have depth")
mesh = engine.mesh()
mesh.save(sys.argv[2])
print(f"{len(mesh.vertices)} vertices, {len(mesh.triangles)} triangles -> {sys.argv[2]}")
