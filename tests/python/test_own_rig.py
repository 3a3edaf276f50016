# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
"""A rig of your own from Python: a 640x480 pair and a 32-beam LiDAR (msf_synth's street seen by
it), whose stages follow the rig as the engine's do, whose calibration saves and loads whole, and
whose camera may give 16-bit images; and the engine's rules for callbacks and threads."""
import threading
import warnings

import numpy as np
import pytest

import msfusion


@pytest.fixture(scope="module")
def own_rig(run_tool, tmp_path_factory):
    out = tmp_path_factory.mktemp("own_rig")
    run_tool("msf_synth", "-o", out, "-frames", 2, "-camera", "pinhole", "-lidar", "hdl32e")
    return msfusion.Sequence(str(out / "sequences" / "00"))


def test_the_stages_follow_the_rig_as_the_engine_does(own_rig):
    """On a rig not of KITTI's sizes the keys in rows between rings scale (adaptToRig): each stage
    object gives the engine's depth, bit for bit."""
    calibration, frame = own_rig.calibration, own_rig[1]
    assert len(calibration.beam_elevations_deg) == calibration.lidar_rings == 32
    engine = msfusion.Reconstructor(calibration).compute_depth(frame)
    lidar_depth, distance = msfusion.LidarCompletion(calibration).compute_depth(frame.scan)
    np.testing.assert_array_equal(lidar_depth, engine.lidar_depth)
    stereo_depth, confidence = msfusion.SgbmStereo(calibration).compute_depth(
        frame.left, frame.right, prior=lidar_depth, guidance=msfusion.real_returns(lidar_depth, distance))
    np.testing.assert_array_equal(stereo_depth, engine.stereo_depth)
    depth, _ = msfusion.DepthFusion(calibration).fuse(lidar_depth, distance, stereo_depth, confidence,
                                                      left=frame.left, sky=frame.color)
    np.testing.assert_array_equal(depth, engine.depth)  # compute_depth leaves the small holes to integration


def test_a_saved_calibration_keeps_its_lidar(own_rig, tmp_path):
    rig = own_rig.calibration
    assert not rig.lidar_sweeping  # the synthetic LiDAR's scans are snapshots
    rig.save_yaml(tmp_path / "rig.yaml")
    again = msfusion.load_calibration(tmp_path / "rig.yaml")
    assert not again.lidar_sweeping
    assert again.lidar_rings == rig.lidar_rings == 32
    np.testing.assert_array_equal(again.beam_elevations_deg, rig.beam_elevations_deg)
    np.testing.assert_array_equal(again.P, rig.P)


def test_a_16_bit_pair_is_scaled_as_the_readers_scale_it(own_rig):
    """A 16-bit camera's pair, v * 257 of the 8-bit one, is that pair again (one gain for both)."""
    frame = own_rig[0]
    assert frame.left.max() >= 128  # so the 16-bit pair spans its 16 bits
    wide = msfusion.Frame(frame.left.astype(np.uint16) * 257, frame.right.astype(np.uint16) * 257, frame.scan,
                          pose=frame.pose)
    np.testing.assert_array_equal(wide.left, frame.left)
    np.testing.assert_array_equal(wide.right, frame.right)
    with pytest.raises(msfusion.InvalidInputError, match="right must be uint16, got uint8"):
        msfusion.Frame(frame.left.astype(np.uint16), frame.right, frame.scan)
    with pytest.raises(msfusion.InvalidInputError, match=r"left must be uint8, got float32 \(scale it to 0..255 first"):
        msfusion.Frame(frame.left.astype(np.float32) / 255, frame.right, frame.scan)


def test_a_float64_scan_is_its_float32_values(own_rig):
    """Open3D's and most numpy code's points are float64: read as the float32 they round to."""
    frame = own_rig[0]
    wide = msfusion.Frame(frame.left, frame.right, frame.scan.astype(np.float64), color=frame.color, pose=frame.pose)
    np.testing.assert_array_equal(wide.scan, frame.scan)
    engine = msfusion.Reconstructor(own_rig.calibration)
    np.testing.assert_array_equal(engine.compute_depth(wide).depth, engine.compute_depth(frame).depth)


def test_a_callback_may_mesh_but_not_feed_the_engine(own_rig):
    engine = msfusion.Reconstructor(own_rig.calibration)
    seen = []

    def on_frame(result):
        seen.append((engine.num_blocks, len(engine.mesh().triangles)))
        if result.index == 1:
            engine.add_frame(own_rig[0])

    with pytest.raises(msfusion.Error, match="addFrame was called within another call of the same engine"):
        engine.run(own_rig, on_frame=on_frame)
    assert len(seen) == 2 and seen[0][0] > 0 and seen[1][1] > 0


@pytest.mark.filterwarnings("ignore:.*the frames are not in time order")  # the threads' frames come in either order
def test_calls_from_two_threads_take_turns(own_rig):
    """The Python engine holds a lock: two threads' frames are both integrated, one after the other."""
    engine = msfusion.Reconstructor(own_rig.calibration)
    errors = []

    def feed(i):
        try:
            engine.add_frame(own_rig[i])
        except Exception as e:  # noqa: BLE001 - the test reports any
            errors.append(e)

    threads = [threading.Thread(target=feed, args=(i,)) for i in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and engine.num_blocks > 0


def test_points_of_a_pose_that_is_not_rigid_are_refused(own_rig):
    camera = own_rig.calibration.camera(0)
    depth = np.ones((camera.height, camera.width), np.float32)
    with pytest.raises(msfusion.InvalidInputError, match="pose is not a rigid transform"):
        msfusion.depth_to_points(depth, camera, pose=np.eye(4) * 3)


def test_run_indexes_frames_as_a_python_sequence(own_rig):
    seen = []
    engine = msfusion.Reconstructor(own_rig.calibration)
    stats = engine.run(own_rig, frames=[-1], on_frame=lambda r: seen.append(r.index))
    assert seen == [1] and stats["frames_done"] == 1
    with pytest.raises(IndexError, match="frame -3 of a source of 2"):
        msfusion.Reconstructor(own_rig.calibration).run(own_rig, frames=[-3])


def test_frames_of_arrays_are_numbered_by_the_engine(own_rig):
    """A frame made of arrays without an index is named by its place among the frames given."""
    engine = msfusion.Reconstructor(own_rig.calibration, poses="given")
    first, second = own_rig[0], own_rig[1]
    result = engine.add_frame(msfusion.Frame(first.left, first.right, first.scan, pose=first.pose))
    assert (result.index, result.name) == (0, "0")
    with pytest.raises(msfusion.InvalidInputError, match="frame 1 has no pose"):
        engine.add_frame(msfusion.Frame(second.left, second.right, second.scan))
    given = engine.add_frame(msfusion.Frame(second.left, second.right, second.scan, pose=second.pose, index=7))
    assert (given.index, given.name) == (7, "7")


def test_a_map_takes_a_result_once(own_rig):
    """A result integrated twice would weigh double: the map refuses it, and another map takes it."""
    engine = msfusion.Reconstructor(own_rig.calibration)
    result = engine.compute_depth(own_rig[0])
    engine.integrate(result)
    once = engine.mesh().vertices.copy()
    with pytest.raises(msfusion.InvalidInputError, match="frame 000000's result is in the map already"):
        engine.integrate(result)
    np.testing.assert_array_equal(engine.mesh().vertices, once)
    with pytest.raises(msfusion.InvalidInputError, match="frame 000001's result is in the map already"):
        engine.integrate(engine.add_frame(own_rig[1]))
    other = msfusion.Reconstructor(own_rig.calibration)
    other.integrate(result)
    np.testing.assert_array_equal(other.mesh().vertices, once)


class MadeOnRead:
    """A program's frames made when asked for, from arrays that go with them."""

    def __init__(self, sequence):
        self.sequence = sequence
        self.reads = []

    def __len__(self):
        return len(self.sequence)

    def __getitem__(self, i):
        self.reads.append(i)
        f = self.sequence[i]
        return msfusion.Frame(f.left.copy(), f.right.copy(), f.scan, color=f.color, pose=f.pose)


def test_run_takes_a_list_of_frames_made_of_arrays(own_rig):
    """run() over frames of arrays, a list or any sequence, gives add_frame's map, their results
    numbered by place, each item read once; an item that is not a Frame is named."""
    frames = [msfusion.Frame(f.left, f.right, f.scan, color=f.color, pose=f.pose) for f in own_rig]
    fed = msfusion.Reconstructor(own_rig.calibration)
    for frame in frames:
        fed.add_frame(frame)
    expected = fed.mesh().vertices
    made_on_read = MadeOnRead(own_rig)
    for source in (frames, made_on_read):
        engine, names = msfusion.Reconstructor(own_rig.calibration), []
        stats = engine.run(source, on_frame=lambda result: names.append((result.index, result.name)))
        assert stats["frames_done"] == 2 and names == [(0, "0"), (1, "1")]
        np.testing.assert_array_equal(engine.mesh().vertices, expected)
    assert sorted(made_on_read.reads) == [0, 1]  # each frame made once
    engine = msfusion.Reconstructor(own_rig.calibration)
    assert engine.run(frames, frames=[-1])["frames_done"] == 1
    with pytest.raises(msfusion.InvalidInputError, match="item 1 of the frames is a str, not a msfusion.Frame"):
        msfusion.Reconstructor(own_rig.calibration).run([frames[0], "000001.png"])
    with pytest.raises(msfusion.InvalidInputError, match="or a sequence of Frame .a list., not a int"):
        msfusion.Reconstructor(own_rig.calibration).run(7)


def test_poses_that_auto_mode_tracked_instead_are_a_warning(own_rig):
    first, second = own_rig[0], own_rig[1]
    engine = msfusion.Reconstructor(own_rig.calibration)  # poses="auto"
    engine.add_frame(msfusion.Frame(first.left, first.right, first.scan, color=first.color))
    with pytest.warns(UserWarning, match="frames with their own pose, from frame 1 on, were tracked by LiDAR "
                                         "odometry instead"):
        engine.add_frame(second)
    assert len(engine.notes) == 1
    again = own_rig[1]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # said once
        engine.add_frame(again)
    with pytest.raises(msfusion.InvalidInputError, match="frame 1 is the frame given last .the same scan."):
        engine.add_frame(again)  # given twice in a row


def test_frames_out_of_time_order_are_a_warning(own_rig):
    """A frame before the one given just before it is taken, and said once."""
    engine = msfusion.Reconstructor(own_rig.calibration)
    engine.add_frame(own_rig[1])
    with pytest.warns(UserWarning, match=r"frame 0 \(at 0 s\) came after a frame at 0.1 s: the frames are not in "
                                         r"time order"):
        engine.add_frame(own_rig[0])
    assert len(engine.notes) == 1 and engine.num_blocks > 0
    f = own_rig[1]
    with pytest.raises(msfusion.InvalidInputError, match="frame 1's timestamp is nan: seconds from the first frame"):
        engine.add_frame(msfusion.Frame(f.left, f.right, f.scan, index=1, timestamp=float("nan")))
