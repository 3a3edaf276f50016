# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""The Python module gives what the C++ tools give on the shared KITTI frames, bit for bit: each
stage against msf_interpolate, msf_stereo and msf_fuse, the pipeline's depth and mesh against
msf_reconstruct's, and the TSDF volume against msf_integrate and msf_mesh."""
import os
import signal

import numpy as np
import pytest

import msfusion

FRAMES = 10  # odometry 04 frames 0-9


@pytest.fixture(scope="module")
def sequence(odometry04):
    return msfusion.Sequence(odometry04)


@pytest.fixture(scope="module")
def tool_chain(odometry04, run_tool, tmp_path_factory):
    """Frames 0-2 through msf_interpolate, msf_stereo, msf_fuse, then msf_integrate and msf_mesh."""
    out = tmp_path_factory.mktemp("tools")
    calib = os.path.join(odometry04, "calib.txt")
    fused = []
    for i in range(3):
        name = f"{i:06d}"
        lidar, stereo = out / f"lidar_{name}.pcd", out / f"stereo_{name}.pcd"
        fused.append(out / f"fused_{name}.pcd")
        image = lambda camera: os.path.join(odometry04, f"image_{camera}", name + ".png")  # noqa: E731
        run_tool("msf_interpolate", os.path.join(odometry04, "velodyne", name + ".bin"), lidar, "-calib", calib)
        run_tool("msf_stereo", image(0), image(1), stereo, "-calib", calib, "-color", image(2), "-prior", lidar)
        run_tool("msf_fuse", lidar, stereo, fused[-1], "-calib", calib, "-color", image(2), "-left", image(0))
    poses = os.path.join(odometry04, "..", "..", "poses", "04.txt")
    run_tool("msf_integrate", *fused, "-poses", poses, "-frames", "0:2", "-calib", calib, "-o", out / "volume.pcd")
    run_tool("msf_mesh", out / "volume.pcd", out / "mesh.ply")
    return out


@pytest.fixture(scope="module")
def reconstructed(odometry04, run_tool, tmp_path_factory):
    """msf_reconstruct on frames 0-9, with each frame's fused depth saved."""
    out = tmp_path_factory.mktemp("reconstruct") / "out"
    run_tool("msf_reconstruct", odometry04, "-o", out, "-frames", f"0:{FRAMES - 1}", "-save_depth", "-panels", "0")
    return out


@pytest.fixture(scope="module")
def per_stage(sequence):
    """Steps 1-4 of frames 0-2 through the per-stage calls, as the pipeline chains them (one
    object per stage for all frames, as a notebook keeps them)."""
    calibration = sequence.calibration
    lidar, stereo = msfusion.LidarCompletion(calibration), msfusion.SgbmStereo(calibration)
    fusion = msfusion.DepthFusion(calibration)
    results = []
    for i in range(3):
        frame = sequence[i]
        lidar_depth, distance = lidar.compute_depth(frame.scan)
        stereo_depth, confidence = stereo.compute_depth(frame.left, frame.right, prior=lidar_depth,
                                                        guidance=msfusion.real_returns(lidar_depth, distance))
        depth, weight = fusion.fuse(lidar_depth, distance, stereo_depth, confidence, left=frame.left,
                                    sky=frame.color)
        filled, filled_weight = fusion.fuse(lidar_depth, distance, stereo_depth, confidence, left=frame.left,
                                            sky=frame.color, fill_holes=True)
        color = msfusion.colorize_depth(depth, calibration, frame.color, fallback=frame.left)
        results.append(dict(lidar=lidar_depth, stereo=stereo_depth, depth=depth, weight=weight, color=color,
                            filled=filled, filled_weight=filled_weight))
    return results


@pytest.fixture(scope="module")
def pipeline_run(sequence):
    """Frames 0-9 through Reconstructor.add_frame: each frame's fused depth, weight and colour, and the
    mesh."""
    engine = msfusion.Reconstructor(sequence.calibration)
    frames = []
    for i in range(FRAMES):
        result = engine.add_frame(sequence[i])
        frames.append(dict(depth=result.depth, weight=result.weight, color=result.color))
    return frames, engine.mesh()


def assert_same_image(a, b, what):
    assert a.shape == b.shape and a.dtype == b.dtype, what
    differ = np.count_nonzero(a != b)
    assert differ == 0, f"{what}: {differ} pixels differ, largest by {np.max(np.abs(a.astype(float) - b))}"


def assert_same_mesh(a, b):
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    np.testing.assert_array_equal(a.colors, b.colors)


def test_each_stage_gives_the_tools_output(sequence, tool_chain, per_stage, pipeline_run):
    camera = sequence.calibration.camera(0)
    for i, ours in enumerate(per_stage):
        lidar, _, _ = msfusion.read_depth_cloud(str(tool_chain / f"lidar_{i:06d}.pcd"), camera)
        stereo, _, _ = msfusion.read_depth_cloud(str(tool_chain / f"stereo_{i:06d}.pcd"), camera)
        fused, weight, color = msfusion.read_depth_cloud(str(tool_chain / f"fused_{i:06d}.pcd"), camera)
        assert np.count_nonzero(fused) > fused.size / 2
        assert_same_image(ours["lidar"], lidar, f"frame {i}: LiDAR depth against msf_interpolate")
        assert_same_image(ours["stereo"], stereo, f"frame {i}: stereo depth against msf_stereo")
        # msf_fuse, as the engine, fills the fusion's small holes at weight 0 (fusion.hole_fill_px).
        assert_same_image(ours["filled"], fused, f"frame {i}: fused depth against msf_fuse")
        has_depth = fused > 0
        assert_same_image(ours["filled_weight"][has_depth], weight[has_depth], f"frame {i}: weight against msf_fuse")
        assert_same_image(ours["color"], color, f"frame {i}: colour against msf_fuse")
        filled = (ours["filled"] > 0) & ~(ours["depth"] > 0)
        assert np.count_nonzero(filled) > 0, f"frame {i}: no hole filled"
        assert np.all(ours["filled_weight"][filled] == 0), f"frame {i}: a filled pixel with a weight"
        assert_same_image(ours["depth"][~filled], ours["filled"][~filled], f"frame {i}: the fill changed a depth")
        pipeline = pipeline_run[0][i]
        assert_same_image(ours["filled"], pipeline["depth"], f"frame {i}: fused depth against the pipeline's")
        assert_same_image(ours["filled_weight"][has_depth], pipeline["weight"][has_depth],
                          f"frame {i}: weight against the pipeline's")
        assert_same_image(ours["color"], pipeline["color"], f"frame {i}: colour against the pipeline's")


def test_the_volume_meshes_as_msf_integrate_and_msf_mesh(sequence, tool_chain):
    """msf_fuse's clouds, integrated here and by msf_integrate (the free space their rays, open sky
    included, passed carved by both), then meshed here and by msf_mesh."""
    volume = msfusion.TsdfVolume()
    camera = sequence.calibration.camera(0)
    open_sky = 0
    for i in range(3):
        cloud = msfusion.read_depth_cloud(tool_chain / f"fused_{i:06d}.pcd", camera)
        depth, weight, color = cloud
        assert cloud.free_space_weight.shape == depth.shape and cloud.sky_depth.shape == depth.shape
        open_sky += np.count_nonzero(~np.isnan(cloud.sky_depth))
        volume.integrate(depth, sequence.poses[i], camera, weight=weight, color=color,
                         free_space_weight=cloud.free_space_weight, sky_depth=cloud.sky_depth)
    assert open_sky > 1000, "frames 0-2 of odometry 04 show no open sky"
    mesh = volume.extract_mesh()
    assert len(mesh.triangles) > 10000
    assert_same_mesh(mesh, msfusion.read_mesh(str(tool_chain / "mesh.ply")))


def test_the_pipeline_gives_msf_reconstructs_depth_and_mesh(sequence, reconstructed, pipeline_run):
    frames, mesh = pipeline_run
    camera = sequence.calibration.camera(0)
    for i, ours in enumerate(frames):
        theirs, weight, _ = msfusion.read_depth_cloud(str(reconstructed / "depth" / f"{i:06d}.pcd"), camera)
        assert_same_image(ours["depth"], theirs, f"frame {i}: fused depth against msf_reconstruct -save_depth")
        has_depth = theirs > 0
        assert_same_image(ours["weight"][has_depth], weight[has_depth], f"frame {i}: weight against msf_reconstruct")
    assert len(mesh.triangles) > 50000
    assert_same_mesh(mesh, msfusion.read_mesh(str(reconstructed / "mesh.ply")))


def test_run_gives_what_add_frame_gives(sequence, pipeline_run):
    """The engine's overlapped run, on its threads, gives the frames and the map add_frame gives."""
    frames, mesh = pipeline_run
    engine = msfusion.Reconstructor(sequence.calibration)
    seen = []

    def on_frame(result):
        ours = frames[result.index]
        assert_same_image(result.depth, ours["depth"], f"frame {result.index}: run's depth against add_frame's")
        seen.append(result.name)

    stats = engine.run(sequence, on_frame=on_frame)
    assert seen == [f"{i:06d}" for i in range(FRAMES)]
    assert stats["frames_done"] == FRAMES and not stats["interrupted"]
    assert_same_mesh(engine.mesh(), mesh)


def test_a_failing_callback_stops_the_run_with_its_error(sequence):
    def on_frame(result):
        raise ValueError(f"stop at {result.name}")

    with pytest.raises(ValueError, match="stop at 000001"):
        msfusion.Reconstructor(sequence.calibration).run(sequence, frames=[1, 2, 3], on_frame=on_frame)
    with pytest.raises(IndexError, match="frame 10 of a source of 10"):
        msfusion.Reconstructor(sequence.calibration).run(sequence, frames=[10])


def test_ctrl_c_stops_a_run_after_the_frame_under_way(sequence):
    class Stop(Exception):
        pass

    def on_sigint(signum, frame):
        raise Stop()

    engine = msfusion.Reconstructor(sequence.calibration)
    done = []
    previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        with pytest.raises(Stop):
            engine.run(sequence, on_frame=lambda r: (done.append(r.index),
                                                     len(done) == 2 and os.kill(os.getpid(), signal.SIGINT)))
    finally:
        signal.signal(signal.SIGINT, previous)
    assert 2 <= len(done) < FRAMES and done == list(range(len(done)))
    assert len(engine.mesh().triangles) > 0  # the frames integrated before the stop are in the map


def test_a_frame_made_of_arrays_gives_the_loaded_frames_depth(sequence):
    loaded = sequence[3]
    made = msfusion.Frame(loaded.left.copy(), loaded.right.copy(), loaded.scan, color=loaded.color,
                          pose=loaded.pose, index=3)
    a = msfusion.Reconstructor(sequence.calibration).compute_depth(loaded)
    b = msfusion.Reconstructor(sequence.calibration).compute_depth(made)
    assert_same_image(a.depth, b.depth, "fused depth of a frame made of arrays")
    assert_same_image(a.weight, b.weight, "weight of a frame made of arrays")
    np.testing.assert_array_equal(a.color, b.color)
