# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The depth of one frame, each stage's and the fused one, as a picture:
PYTHONPATH=build/python /usr/bin/python3 examples/python/depth_of_one_frame.py SEQUENCE_DIR FRAME_INDEX OUT.png
(from the repository, with the build tree's module; see docs/python.md)"""
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed: the figure goes to a file
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import msfusion  # noqa: E402

if len(sys.argv) < 4:
    sys.exit(__doc__)  # the usage

sequence = msfusion.Sequence(sys.argv[1])
frame = sequence[int(sys.argv[2])]
result = msfusion.Reconstructor(sequence.calibration).compute_depth(frame)  # steps 1-4, each stage's depth

panels = [("left image (camera 0)", frame.left, "gray"),
          ("interpolated LiDAR", result.lidar_depth, "turbo"),
          ("SGBM", result.stereo_depth, "turbo"),
          ("fused", result.depth, "turbo")]
figure, axes = plt.subplots(len(panels), 1, figsize=(12, 3.2 * len(panels)))
for ax, (title, image, colormap) in zip(axes, panels):
    if colormap == "gray":
        ax.imshow(image, cmap="gray")
    else:  # no depth (0) in black, 3 to 60 m in colour
        shown = ax.imshow(np.ma.masked_equal(image, 0), cmap=colormap, vmin=3, vmax=60)
        shown.cmap.set_bad("black")
        figure.colorbar(shown, ax=ax, label="depth (m)", fraction=0.02)
    ax.set_title(f"{title}, frame {frame.name}")
    ax.axis("off")
figure.tight_layout()
figure.savefig(sys.argv[3], dpi=80)
print(f"fused depth at {(result.depth > 0).mean():.0%} of the pixels -> {sys.argv[3]}")
