#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The Python module's per-frame cost against the C++ engine's, in one run: KITTI odometry 04
frames 0-9, one frame after the other through Reconstructor.add_frame (depth, pose, integration)
into a fresh engine, as bench_frame_loop (C++) does; rounds alternate between the two, and the
medians are compared: wall time, and the process's CPU time (all threads), which other work on
a shared machine disturbs less.

    PYTHONPATH=build/python python3 bench/bench_python.py build/bin ../shared/data/kitti [ROUNDS]

Four Python paths, each against its C++ counterpart:
  load + add_frame   Sequence[i] read in the loop          vs BM_LoadAndAddFrame
  add_frame          the frames read before the timing     vs BM_AddFrame
  arrays + add_frame a Frame made of numpy arrays per frame vs BM_AddFrame
                     (the grey pair viewed, the scan and the colour image copied)
  run(list)          a list of those Frames through run(), overlapped on the engine's threads
                     vs BM_Run (the sequence read by run())
"""
import json
import os
import statistics
import subprocess
import sys
import time

import msfusion

FRAMES = 10


def cpp_round(bin_dir, kitti_dir):
    """(wall, CPU) ms per frame of BM_LoadAndAddFrame, BM_AddFrame and BM_Run, one process."""
    r = subprocess.run([os.path.join(bin_dir, "bench_frame_loop"), "--benchmark_format=json"], capture_output=True,
                       text=True, check=True, env=dict(os.environ, MSF_KITTI_DIR=kitti_dir))
    times = {b["name"].split("/")[0]: (b["real_time"] / FRAMES, b["cpu_time"] / FRAMES)
             for b in json.loads(r.stdout)["benchmarks"]}
    return times["BM_LoadAndAddFrame"], times["BM_AddFrame"], times["BM_Run"]


def timed(calibration, frames):
    """(wall, CPU) ms per frame of adding `frames` (a callable per index giving a Frame) to a fresh
    engine."""
    wall, cpu = time.perf_counter(), time.process_time()
    engine = msfusion.Reconstructor(calibration)
    for i in range(FRAMES):
        engine.add_frame(frames(i))
    return (time.perf_counter() - wall) * 1000 / FRAMES, (time.process_time() - cpu) * 1000 / FRAMES


def timed_run(calibration, frames):
    """(wall, CPU) ms per frame of run() over the list `frames` in a fresh engine."""
    wall, cpu = time.perf_counter(), time.process_time()
    msfusion.Reconstructor(calibration).run(frames)
    return (time.perf_counter() - wall) * 1000 / FRAMES, (time.process_time() - cpu) * 1000 / FRAMES


def python_round(sequence, loaded, arrays):
    return (timed(sequence.calibration, lambda i: sequence[i]),
            timed(sequence.calibration, lambda i: loaded[i]),
            timed(sequence.calibration, lambda i: msfusion.Frame(**arrays[i])),
            timed_run(sequence.calibration, [msfusion.Frame(**a) for a in arrays]))


def cpu_model():
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def main():
    bin_dir, kitti_dir = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    sequence = msfusion.Sequence(os.path.join(kitti_dir, "odometry", "sequences", "04"))
    loaded = [sequence[i] for i in range(FRAMES)]
    arrays = [dict(left=f.left.copy(), right=f.right.copy(), scan=f.scan, color=f.color, pose=f.pose, index=i)
              for i, f in enumerate(loaded)]
    python_round(sequence, loaded, arrays)  # warm-up, as bench_frame_loop does
    cpp, python = [], []
    for k in range(rounds):
        cpp.append(cpp_round(bin_dir, kitti_dir))
        python.append(python_round(sequence, loaded, arrays))
        print(f"round {k + 1}/{rounds}, wall ms per frame: C++ " + " ".join(f"{t[0]:.1f}" for t in cpp[-1]) +
              ", Python " + " ".join(f"{t[0]:.1f}" for t in python[-1]), flush=True)
    print(f"\nKITTI odometry 04 frames 0-{FRAMES - 1}, ms per frame, median of {rounds} alternating rounds; "
          f"{os.cpu_count()} cores, {cpu_model()}")
    print(f"{'path':<20} {'C++ wall':>9} {'Python':>8} {'ratio':>6}   {'C++ CPU':>8} {'Python':>8} {'ratio':>6}")
    for name, c, p in (("load + add_frame", 0, 0), ("add_frame", 1, 1), ("arrays + add_frame", 1, 2),
                       ("run(list)", 2, 3)):
        row = f"{name:<20}"
        for clock in (0, 1):
            a = statistics.median(r[c][clock] for r in cpp)
            b = statistics.median(r[p][clock] for r in python)
            row += f" {a:9.1f} {b:8.1f} {b / a:6.3f}  "
        print(row)


if __name__ == "__main__":
    main()
