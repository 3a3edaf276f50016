# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""Shapes, dtypes and errors: what the binding takes and gives, and how it refuses."""
import copy
import errno
import gc
import math
import os
import pickle
import threading
import time

import numpy as np
import pytest

import msfusion


@pytest.fixture(scope="module")
def calibration(odometry04):
    return msfusion.load_calibration(os.path.join(odometry04, "calib.txt"))


@pytest.fixture(scope="module")
def sequence(odometry04):
    return msfusion.Sequence(odometry04)


@pytest.fixture(scope="module")
def frame(sequence):
    return sequence[0]


def test_errors_are_library_kinds_and_python_builtins():
    assert issubclass(msfusion.Error, RuntimeError)
    assert issubclass(msfusion.IOError, msfusion.Error) and issubclass(msfusion.IOError, OSError)
    for kind in (msfusion.ConfigError, msfusion.CalibrationError, msfusion.InvalidInputError):
        assert issubclass(kind, msfusion.Error) and issubclass(kind, ValueError)
    with pytest.raises(msfusion.IOError, match="/nonexistent/calib.txt"):
        msfusion.load_calibration("/nonexistent/calib.txt")
    with pytest.raises(OSError):
        msfusion.Sequence("/nonexistent/sequence")


def test_a_missing_or_misplaced_file_is_the_builtin_oserror_with_errno_and_filename(odometry04, tmp_path):
    missing = str(tmp_path / "none")
    calls = [
        (lambda: msfusion.load_calibration(missing), FileNotFoundError, missing, f"calibration '{missing}' does not"),
        (lambda: msfusion.open_dataset(missing), FileNotFoundError, missing, f"sequence '{missing}' does not exist"),
        (lambda: msfusion.load_config(missing), FileNotFoundError, missing, f"config '{missing}' does not exist"),
        (lambda: msfusion.read_mesh(missing + ".ply"), FileNotFoundError, missing + ".ply", "mesh '"),
        (lambda: msfusion.Sequence(os.path.join(odometry04, "calib.txt")), NotADirectoryError,
         os.path.join(odometry04, "calib.txt"), "sequence '"),
    ]
    for call, builtin, path, message in calls:
        with pytest.raises(builtin) as raised:
            call()
        error = raised.value
        assert isinstance(error, msfusion.IOError) and isinstance(error, msfusion.Error)
        assert error.errno == {FileNotFoundError: errno.ENOENT, NotADirectoryError: errno.ENOTDIR}[builtin]
        assert error.filename == path and error.strerror == os.strerror(error.errno)
        assert str(error).startswith(message), str(error)  # the library's message, not "[Errno 2] ..."
    # A file whose content is wrong has no errno: an IOError, and no built-in's subclass.
    (tmp_path / "bad.ply").write_text("not a mesh\n")
    with pytest.raises(msfusion.IOError) as raised:
        msfusion.read_mesh(str(tmp_path / "bad.ply"))
    assert raised.value.errno is None and not isinstance(raised.value, FileNotFoundError)


def test_a_calibration_missing_a_key_names_it(odometry04, tmp_path):
    lines = open(os.path.join(odometry04, "calib.txt")).read().splitlines()
    (tmp_path / "calib.txt").write_text("\n".join(l for l in lines if not l.startswith("P2")) + "\n")
    with pytest.raises(msfusion.CalibrationError, match="P2"):
        msfusion.load_calibration(str(tmp_path / "calib.txt"))


def test_the_calibration_is_the_files(calibration, odometry04, tmp_path):
    rows = {l.split(":")[0]: np.array(l.split(":")[1].split(), dtype=float)
            for l in open(os.path.join(odometry04, "calib.txt")) if ":" in l}
    assert calibration.image_size == (1226, 370)  # the size of image_0/000000.png beside it
    assert calibration.P.shape == (4, 3, 4)
    for i in range(4):
        np.testing.assert_array_equal(calibration.P[i], rows[f"P{i}"].reshape(3, 4))
    np.testing.assert_array_equal(calibration.T_cam0_velo[:3], rows["Tr"].reshape(3, 4))
    assert calibration.focal_baseline == pytest.approx(-rows["P1"][3])
    camera = calibration.camera(0)
    assert (camera.width, camera.height, camera.fx) == (1226, 370, pytest.approx(rows["P0"][0]))
    calibration.save_yaml(str(tmp_path / "rig.yaml"))  # the project's YAML rig reads back the same
    again = msfusion.load_calibration(str(tmp_path / "rig.yaml"))
    np.testing.assert_allclose(again.P, calibration.P, rtol=1e-12)
    assert again.image_size == calibration.image_size


def test_the_rig_says_how_its_lidar_takes_scans(calibration, run_tool, tmp_path):
    assert calibration.lidar_sweeping  # KITTI's Velodyne spins
    run_tool("msf_synth", "-o", tmp_path / "street", "-frames", 2)
    street = msfusion.Sequence(str(tmp_path / "street" / "sequences" / "00"))
    assert not street.calibration.lidar_sweeping  # the synthetic LiDAR's scans are snapshots
    rig = street.calibration
    rig.lidar_sweeping = True
    assert not street.calibration.lidar_sweeping  # a copy: the sequence's rig is as it was
    rig.save_yaml(str(tmp_path / "rig.yaml"))
    assert msfusion.load_calibration(str(tmp_path / "rig.yaml")).lidar_sweeping


def test_a_raw_date_folder_is_a_calibration(kitti_dir):
    calibration = msfusion.load_calibration(os.path.join(kitti_dir, "raw", "2011_09_26"))
    assert calibration.image_size == (1242, 375) and calibration.has_velodyne


def test_a_sequence_is_an_iterable_of_frames(kitti_dir, odometry04):
    drive = msfusion.Sequence(os.path.join(kitti_dir, "raw", "2011_09_26", "2011_09_26_drive_0009_sync"))
    assert (len(drive), drive.layout, drive.poses.shape) == (5, "raw", (5, 4, 4))
    frames = list(drive)
    assert [f.name for f in frames] == [f"{i:010d}" for i in range(5)]
    last = frames[-1]
    assert last.left.shape == (375, 1242) and last.left.dtype == np.uint8
    assert last.color.shape == (375, 1242, 3) and last.color.dtype == np.uint8
    assert last.scan.ndim == 2 and last.scan.shape[1] == 4 and last.scan.dtype == np.float32
    np.testing.assert_array_equal(last.pose, drive.poses[4])
    np.testing.assert_array_equal(drive[-1].left, last.left)
    odometry = msfusion.Sequence(odometry04)
    scan = np.fromfile(os.path.join(odometry04, "velodyne", "000007.bin"), np.float32).reshape(-1, 4)
    np.testing.assert_array_equal(odometry[7].scan, scan)  # the .bin as it is on disk
    np.testing.assert_allclose(odometry.poses[0], np.eye(4), atol=1e-9)  # poses/04.txt starts at the identity
    with pytest.raises(IndexError):
        odometry[10]
    opened = msfusion.open_dataset(odometry04)  # as msf_reconstruct opens it: the Sequence under FrameSource
    assert isinstance(opened, msfusion.Sequence) and isinstance(opened, msfusion.FrameSource) and len(opened) == 10
    with pytest.raises(msfusion.IOError, match="/nonexistent/drive"):
        msfusion.open_dataset("/nonexistent/drive")


def test_a_bag_opens_by_its_topics(odometry04, bin_dir, run_tool, tmp_path):
    if not os.path.exists(os.path.join(bin_dir, "msf_kitti2bag")):
        pytest.skip("a build without the ROS module")
    bag = tmp_path / "04.bag"
    run_tool("msf_kitti2bag", odometry04, "-frames", "0:1", "-o", bag)
    opened = msfusion.open_dataset(bag)  # kitti2bag's topics, as msf_reconstruct reads them
    assert len(opened) == 2 and opened.has_color
    grey = msfusion.open_dataset(bag, color_topic="")
    assert len(grey) == 2 and not grey.has_color and isinstance(grey.notes, list)
    np.testing.assert_array_equal(grey[1].left, opened[1].left)
    assert opened.calibration.lidar_sweeping  # a bag does not say: swept, unless told
    assert not msfusion.open_dataset(bag, sweeping_scans=False).calibration.lidar_sweeping
    with pytest.raises(msfusion.InvalidInputError, match="has no topic '/velodyne_points' where the LiDAR's scans"):
        msfusion.open_dataset(bag, lidar_topic="/velodyne_points")
    with pytest.raises(msfusion.InvalidInputError, match="bag topics and frames are for a ROS bag"):
        msfusion.open_dataset(odometry04, lidar_topic="/velodyne_points")


def test_stage_outputs_are_owned_contiguous_arrays(calibration, frame):
    lidar = msfusion.LidarCompletion(calibration)
    depth, distance = lidar.compute_depth(frame.scan)
    for image in (depth, distance):
        assert image.shape == (370, 1226) and image.dtype == np.float32
        assert image.flags.c_contiguous and image.flags.owndata is False and image.flags.writeable
    del lidar  # the arrays own their memory, not the stage
    assert np.count_nonzero(depth) > depth.size / 2 and np.all(distance[depth > 0] >= 0)
    stereo_depth, confidence = msfusion.SgbmStereo(calibration).compute_depth(frame.left, frame.right)
    assert stereo_depth.shape == confidence.shape == (370, 1226)
    assert 0 <= confidence.min() and confidence.max() <= 1
    fused = msfusion.DepthFusion(calibration).fuse(depth, distance, stereo_depth, confidence, free_space=True)
    assert len(fused) == 3 and all(a.shape == (370, 1226) and a.dtype == np.float32 for a in fused)


def test_images_on_huge_pages_are_the_same_values_on_2_mib_boundaries(calibration, frame):
    with open("/sys/kernel/mm/transparent_hugepage/enabled") as f:
        if "[never]" in f.read():
            pytest.skip("this system has no transparent huge pages")
    lidar = msfusion.LidarCompletion(calibration)
    before, _ = lidar.compute_depth(frame.scan)
    msfusion.use_huge_pages_for_large_images()
    after, _ = lidar.compute_depth(frame.scan)
    assert after.ctypes.data % (2 << 20) == 0 and before.ctypes.data % (2 << 20) != 0
    np.testing.assert_array_equal(after, before)


def test_inputs_are_viewed_and_results_are_views(frame):
    left, right = frame.left.copy(), frame.right.copy()
    made = msfusion.Frame(left, right, frame.scan)
    assert np.shares_memory(made.left, left) and np.shares_memory(made.right, right)
    assert np.shares_memory(frame.left, frame.left)  # a loaded frame's image is a view of the frame
    assert made.pose is None and made.color is None and made.scan.shape == frame.scan.shape


def test_a_result_outlives_the_arrays_of_its_frame(calibration, frame):
    left = frame.left.copy()
    expected = left.copy()
    made = msfusion.Frame(left, frame.right.copy(), frame.scan, pose=frame.pose)
    result = msfusion.Reconstructor(calibration).add_frame(made)
    del made, left  # numpy unmaps a buffer this large: a view of it would now fault
    gc.collect()
    np.testing.assert_array_equal(result.left, expected)


def test_wrong_arrays_are_errors_naming_the_argument(calibration, frame):
    stereo = msfusion.SgbmStereo(calibration)
    fusion = msfusion.DepthFusion(calibration)
    depth = np.zeros((370, 1226), np.float32)
    cases = [
        (lambda: stereo.compute_depth(frame.left.astype(np.float32), frame.right), "left must be uint8, got float32"),
        (lambda: stereo.compute_depth(frame.left[:, :100], frame.right), "left must be C-contiguous"),
        (lambda: stereo.compute_depth(frame.left, frame.right[:100].copy()), "right is 1226x100 .W x H., expected 1226x370"),
        (lambda: stereo.compute_depth(frame.left.tolist(), frame.right), "left must be a numpy array, got list"),
        (lambda: fusion.fuse(depth.astype(np.float64), None, depth, None), "lidar_depth must be float32, got float64"),
        (lambda: fusion.fuse(depth, None, depth[None], None), r"stereo_depth must have shape \(H, W\), got \(1, 370, 1226\)"),
        (lambda: fusion.fuse(depth, depth.T, depth, None), "lidar_distance must be C-contiguous"),
        (lambda: msfusion.LidarCompletion(calibration).compute_depth(frame.scan[:, :2].copy()),
         r"scan must have shape \(N, 3\) or \(N, 4\), got \(\d+, 2\)"),
        (lambda: msfusion.LidarCompletion(calibration, method="bilinear"), "bilinear"),
        (lambda: msfusion.TsdfVolume().integrate(depth, np.eye(4), calibration, sky_depth=depth.astype(np.float64)),
         "sky_depth must be float32, got float64"),
        (lambda: msfusion.TsdfVolume().integrate(depth, np.eye(4), calibration, sky_depth=depth[:100].copy()),
         r"sky_depth is 1226x100 .W x H., expected 1226x370"),
    ]
    for call, message in cases:
        with pytest.raises(msfusion.InvalidInputError, match=message):
            call()


def test_poses_must_be_rigid():
    volume = msfusion.TsdfVolume()
    camera = msfusion.PinholeCamera(100, 100, 50, 40, 100, 80)
    depth = np.full((80, 100), 2.0, np.float32)
    with pytest.raises(msfusion.InvalidInputError, match=r"pose must have shape \(4, 4\)"):
        volume.integrate(depth, np.eye(3), camera)
    scaled = np.diag([2.0, 2.0, 2.0, 1.0])
    with pytest.raises(msfusion.InvalidInputError, match="pose"):
        volume.integrate(depth, scaled, camera)
    with pytest.raises(msfusion.InvalidInputError, match="camera must be a msfusion.PinholeCamera"):
        volume.integrate(depth, np.eye(4), "camera 0")


def test_a_sky_depth_bound_of_zero_is_refused_before_the_volume_changes():
    volume = msfusion.TsdfVolume()
    camera = msfusion.PinholeCamera(100, 100, 50, 40, 100, 80)
    depth = np.full((80, 100), 2.0, np.float32)
    sky = np.full((80, 100), np.nan, np.float32)
    sky[3, 7] = 0.0
    with pytest.raises(msfusion.InvalidInputError,
                       match=r"sky depth at pixel \(7, 3\) is 0\.0+: a pixel's bound is NaN \(not sky\), a depth > 0"):
        volume.integrate(depth, np.eye(4), camera, sky_depth=sky)
    assert volume.num_blocks == 0
    sky[3, 7] = np.inf  # the whole ray
    volume.integrate(depth, np.eye(4), camera, sky_depth=sky)
    assert volume.num_blocks > 0


def test_a_frame_without_pose_takes_the_odometrys_or_is_refused(calibration, sequence):
    def bare(i):  # the frame as a driver without poses gives it
        f = sequence[i]
        return msfusion.Frame(f.left, f.right, f.scan, index=i)

    given = msfusion.Reconstructor(calibration, poses="given")
    with pytest.raises(msfusion.InvalidInputError, match="has no pose"):
        given.add_frame(bare(0))
    result = given.compute_depth(bare(0))
    assert result.pose is None and result.depth.shape == (370, 1226)
    result.pose = np.eye(4)  # given one, it is integrated
    given.integrate(result)
    assert given.num_blocks > 0
    auto = msfusion.Reconstructor(calibration)  # poses="auto": the LiDAR odometry's, from the first frame's
    poses = [auto.add_frame(bare(i)).pose for i in range(3)]
    np.testing.assert_allclose(poses[0], np.eye(4), atol=1e-6)
    assert np.linalg.norm(poses[2][:3, 3] - sequence.poses[2][:3, 3]) < 0.1  # the vehicle drove ~2 m
    assert len(auto.odometry_ms) == 3
    with pytest.raises(msfusion.InvalidInputError, match="poses must be auto, given, odometry or refine, not 'gps'"):
        msfusion.Reconstructor(calibration, poses="gps")


def test_config_overrides_are_read_as_a_file_reads():
    config = msfusion.load_config(overrides={"tsdf_volume.voxel_size_m": 0.2, "tsdf_integrator": {"lambda": 5.0}})
    assert config.voxel_size == 0.2 and "lambda: 5" in config.yaml()
    assert msfusion.TsdfVolume(config).voxel_size == 0.2
    with pytest.raises(msfusion.ConfigError, match=r"^overrides: tsdf_volume.voxel_size_m must be .* not -1"):
        msfusion.load_config(overrides={"tsdf_volume.voxel_size_m": -1.0})
    with pytest.raises(msfusion.ConfigError, match="^overrides: 'fusion.no_such_key' is not a key of section 'fusion'"):
        msfusion.load_config(overrides={"fusion.no_such_key": 1})
    with pytest.raises(msfusion.IOError, match="/nonexistent.yaml"):
        msfusion.load_config("/nonexistent.yaml")


def test_a_string_override_is_a_string_as_in_a_file():
    assert "mode: sgbm" in msfusion.load_config(overrides={"stereo.mode": "sgbm"}).yaml()
    with pytest.raises(msfusion.ConfigError, match=r"^overrides: .*voxel_size_m"):  # "0.2" is text, not 0.2
        msfusion.load_config(overrides={"tsdf_volume.voxel_size_m": "0.2"})
    with pytest.raises(msfusion.ConfigError, match="^overrides: .*stereo.mode"):  # YAML's syntax stays text
        msfusion.load_config(overrides={"stereo.mode": "sgbm\nfusion: {method: x}"})


def test_a_rig_from_its_numbers_is_the_rig_its_file_gives(calibration, frame):
    K, (width, height) = calibration.K(0), calibration.image_size
    mine = msfusion.Calibration(width=width, height=height, fx=K[0, 0], fy=K[1, 1], cx=K[0, 2], cy=K[1, 2],
                                baseline=calibration.baseline(0, 1), T_cam_lidar=calibration.T_cam0_velo)
    np.testing.assert_allclose(mine.P[:2], calibration.P[:2], rtol=1e-12, atol=1e-9)
    np.testing.assert_array_equal(mine.T_cam0_velo, calibration.T_cam0_velo)
    results = [msfusion.Reconstructor(rig).compute_depth(frame) for rig in (calibration, mine)]
    np.testing.assert_allclose(results[1].depth, results[0].depth, rtol=1e-5, atol=1e-5)
    assert 0 <= results[0].lidar_stereo_disagreement < 0.1  # the two sensors of a right rig agree
    assert not msfusion.Calibration(640, 480, 500, 500, 320, 240, 0.12).has_velodyne  # cameras only
    with pytest.raises(msfusion.CalibrationError, match="the baseline must be > 0"):
        msfusion.Calibration(640, 480, 500, 500, 320, 240, -0.12)
    with pytest.raises(msfusion.CalibrationError, match="focal lengths must be > 0"):
        msfusion.Calibration(640, 480, 0, 500, 320, 240, 0.12)
    with pytest.raises(msfusion.InvalidInputError, match="T_cam_lidar"):
        msfusion.Calibration(640, 480, 500, 500, 320, 240, 0.12, T_cam_lidar=2 * np.eye(4))
    with pytest.raises(msfusion.CalibrationError, match="must rise"):
        msfusion.Calibration(640, 480, 500, 500, 320, 240, 0.12, np.eye(4), beam_elevations_deg=[2.0, -2.0])


def test_a_calibration_copies_and_pickles_to_the_same_rig(calibration):
    for twin in (copy.copy(calibration), copy.deepcopy(calibration), pickle.loads(pickle.dumps(calibration))):
        np.testing.assert_array_equal(twin.P, calibration.P)
        np.testing.assert_array_equal(twin.T_cam0_velo, calibration.T_cam0_velo)
        assert repr(twin) == repr(calibration) and twin.image_size == calibration.image_size
        twin.lidar_sweeping = not calibration.lidar_sweeping  # a copy, not the rig itself
        assert twin.lidar_sweeping != calibration.lidar_sweeping


def test_a_config_copies_and_pickles_to_the_same_keys():
    config = msfusion.load_config(overrides={"tsdf_volume.voxel_size_m": 0.2, "stereo.mode": "sgbm"})
    for twin in (copy.copy(config), copy.deepcopy(config), pickle.loads(pickle.dumps(config))):
        assert twin == config and twin.yaml() == config.yaml() and twin.voxel_size == 0.2
    assert config != msfusion.Config()
    assert msfusion.Config.from_yaml(config.yaml()) == config
    with pytest.raises(msfusion.ConfigError, match="^config 'mine' line 2: .*voxel_size_m"):
        msfusion.Config.from_yaml("tsdf_volume:\n  voxel_size_m: -1\n", "mine")


def test_heavy_calls_release_the_gil(calibration, frame):
    """Python code runs while a stage works: a loop of ~0.1 s of bytecode ends while stereo
    matches of ~1 s in all (as many as this host needs) are still running. Were the GIL held,
    the loop would run only between two matches, ~5 ms each time (the switch interval), and end
    after the worker."""

    def spin(n):
        for _ in range(n):
            pass

    start = time.perf_counter()
    spin(1_000_000)
    loop = int(1_000_000 * 0.1 / (time.perf_counter() - start))
    stereo = msfusion.SgbmStereo(calibration)
    start = time.perf_counter()
    stereo.compute_depth(frame.left, frame.right)
    matches = max(5, math.ceil(1.0 / (time.perf_counter() - start)))
    started, done = threading.Event(), threading.Event()

    def match():
        started.set()
        for _ in range(matches):
            stereo.compute_depth(frame.left, frame.right)
        done.set()

    worker = threading.Thread(target=match)
    worker.start()
    started.wait()
    time.sleep(0.02)  # inside the first match
    spin(loop)
    assert not done.is_set(), "the Python loop waited for the stereo matches: the GIL was held"
    worker.join()


def test_values_that_are_no_depth_weight_or_confidence_are_refused(calibration):
    fusion = msfusion.DepthFusion(calibration)
    depth = np.full((370, 1226), 10, np.float32)
    inf_depth = depth.copy()
    inf_depth[5, 7] = np.inf  # what focal_baseline / disparity gives where the disparity is 0
    volume = msfusion.TsdfVolume()
    cases = [
        (lambda: fusion.fuse(depth, None, inf_depth, None),
         "stereo_depth holds inf at row 5, column 7: give 0 or NaN where there is no depth"),
        (lambda: fusion.fuse(inf_depth, None, depth, None), "lidar_depth holds inf at row 5, column 7"),
        (lambda: fusion.fuse(depth, None, depth, np.full_like(depth, np.nan)),
         "stereo_confidence holds nan at row 0, column 0: a confidence is 0..1"),
        (lambda: fusion.fuse(depth, -depth, depth, None), "lidar_distance holds -10 at row 0, column 0"),
        (lambda: volume.integrate(depth, np.eye(4), calibration, weight=np.full_like(depth, np.nan)),
         r"weight holds nan at row 0, column 0: a weight is an inverse variance \(m\^-2\), finite and not negative"),
        (lambda: volume.integrate(depth, np.eye(4), calibration, weight=-depth), "weight holds -10 at row 0"),
    ]
    for call, message in cases:
        with pytest.raises(msfusion.InvalidInputError, match=message):
            call()
    assert volume.extract_mesh().vertices.shape[0] == 0  # nothing was integrated
    # NaN is no depth, as 0 is: the stereo depth alone, finite weights.
    fused, weight = fusion.fuse(np.full_like(depth, np.nan), None, depth, None)
    assert np.all(np.isfinite(weight)) and np.count_nonzero(fused) > 0


def test_inputs_are_never_written(calibration, frame):
    stages = msfusion.LidarCompletion(calibration), msfusion.SgbmStereo(calibration), msfusion.DepthFusion(calibration)
    depth, distance = stages[0].compute_depth(frame.scan)
    stereo_depth, confidence = stages[1].compute_depth(frame.left, frame.right, prior=depth)
    color = frame.color
    before = color.copy()
    first, _ = stages[2].fuse(depth, distance, stereo_depth, confidence, left=frame.left, sky=color)
    np.testing.assert_array_equal(color, before)  # RGB still, not turned into the library's BGR
    again, _ = stages[2].fuse(depth, distance, stereo_depth, confidence, left=frame.left, sky=color)
    np.testing.assert_array_equal(again, first)
    # A frame made from a read-only image gives that image back, read-only.
    left = frame.left.copy()
    left.flags.writeable = False
    made = msfusion.Frame(left, frame.right.copy(), frame.scan)
    assert made.left is left and not made.left.flags.writeable


def test_a_camera_index_outside_0_to_3_is_refused(calibration):
    for call in (lambda: calibration.K(4), lambda: calibration.K(-1), lambda: calibration.baseline(0, 100000)):
        with pytest.raises(msfusion.InvalidInputError, match=r"camera index (4|-1|100000) is not 0\.\.3"):
            call()
    np.testing.assert_allclose(calibration.K(3)[2], [0, 0, 1])
    with pytest.raises(msfusion.InvalidInputError, match="a PinholeCamera needs fx, fy > 0 and finite"):
        msfusion.PinholeCamera(0, 0, 0, 0, 0, 0)
    with pytest.raises(msfusion.InvalidInputError, match="image size 100000x480 is outside"):
        msfusion.PinholeCamera(500, 500, 320, 240, 100000, 480)


def test_a_mesh_without_colours_is_saved_without_them(tmp_path):
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
    mesh = msfusion.Mesh(vertices, np.array([[0, 1, 2]], np.int32))
    for extension in ("ply", "obj", "vtk"):
        mesh.save(str(tmp_path / ("triangle." + extension)))
    with pytest.raises(msfusion.InvalidInputError, match="cannot write mesh '.*empty.ply': it has no vertices"):
        msfusion.TsdfVolume().extract_mesh().save(tmp_path / "empty.ply")
    assert not (tmp_path / "empty.ply").exists()
    back = msfusion.read_mesh(str(tmp_path / "triangle.ply"))
    np.testing.assert_array_equal(back.vertices, vertices)
    np.testing.assert_array_equal(back.triangles, [[0, 1, 2]])


def test_help_documents_every_public_name():
    import pydoc

    text = pydoc.render_doc(msfusion, renderer=pydoc.plaintext)
    for name in msfusion.__all__:
        assert hasattr(msfusion, name), name
        assert name in text, name
    for name in ("class Reconstructor", "class TsdfVolume", "class DepthFusion", "load_config(", "depth_to_points("):
        assert name in text, name


def test_a_path_may_be_a_pathlib_path(odometry04, tmp_path):
    import pathlib

    folder = pathlib.Path(odometry04)
    assert len(msfusion.Sequence(folder)) == len(msfusion.open_dataset(folder)) > 0
    calibration = msfusion.load_calibration(folder / "calib.txt")
    calibration.save_yaml(tmp_path / "rig.yaml")
    np.testing.assert_array_equal(msfusion.load_calibration(tmp_path / "rig.yaml").K(), calibration.K())
    (tmp_path / "config.yaml").write_text("tsdf_volume:\n  voxel_size_m: 0.2\n")
    assert "voxel_size_m: 0.2" in msfusion.load_config(tmp_path / "config.yaml").yaml()
    mesh = msfusion.Mesh(np.eye(3, dtype=np.float32), np.array([[0, 1, 2]], np.int32))
    mesh.save(tmp_path / "mesh.ply")
    np.testing.assert_array_equal(msfusion.read_mesh(tmp_path / "mesh.ply").vertices, np.eye(3))
    volume = msfusion.TsdfVolume()
    volume.integrate_points(np.array([[5, 0, 0], [5, 0.5, 0]], np.float32), np.eye(4))
    volume.save(tmp_path / "volume.pcd")
    assert (tmp_path / "volume.pcd").stat().st_size > 0


def test_frames_are_indexed_and_sliced_as_a_python_sequence(sequence):
    names = [sequence.frame_name(i) for i in range(len(sequence))]
    assert sequence.frame_name(-1) == names[-1]
    assert [f.name for f in sequence[1:6:2]] == names[1:6:2]
    assert [f.name for f in sequence[::-3]] == names[::-3]
    size = len(sequence)
    with pytest.raises(IndexError, match="frame %d of a source of %d" % (size, size)):
        sequence.frame_name(size)
    with pytest.raises(IndexError, match="frame %d of a source of %d" % (-size - 1, size)):
        sequence[-size - 1]


def test_the_version_is_the_tools(run_tool):
    import re

    assert run_tool("msf_info", "--version").stdout.startswith("msf_info (msfusion) %s, commit " % msfusion.__version__)
    assert re.fullmatch(r"[0-9a-f]{12}(-dirty)?|unknown", msfusion.__commit__)
