// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// What the pipeline hands to evaluation protocol 4: frames changed before any stage sees
// them (the ring hold-out), and each source's depth as a frame to integrate alone.
#include <msf/common/exceptions.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/source_depth_frame.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/range_image/ring_split.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <opencv2/core.hpp>

#include <array>
#include <map>
#include <set>
#include <mutex>
#include <thread>

namespace {

/// Runs frames 0-1 of `dataset` with a frame filter that keeps the input rings of the ring
/// hold-out, and checks that the pipeline's step 1 saw exactly those.
void checkTheFilterComesFirst(const std::string& dataset) {
  const msf::Sequence sequence(dataset);
  const auto frames = sequence.indices(msf::FrameRange::parse("0:1"));
  const msf::PipelineConfig config;
  msf::Reconstructor::Options options;
  options.keep_sparse = true; // the projected scan step 1 worked on
  msf::Reconstructor pipeline(sequence.calibration(), config, options);
  // The filter keeps the input rings and remembers, per frame, what it removed and kept.
  std::mutex mutex;
  std::map<std::size_t, pcl::PointCloud<pcl::PointXYZI>> kept, removed;
  std::vector<std::size_t> filtered;
  const std::thread::id caller = std::this_thread::get_id();
  pipeline.setFrameFilter([&](msf::Frame& frame) {
    EXPECT_NE(std::this_thread::get_id(), caller); // on the loading thread
    pcl::PointCloud<pcl::PointXYZI> input, heldout;
    msf::splitRings(*frame.scan, msf::RingSplitConfig{}, input, heldout);
    *frame.scan = input;
    const std::lock_guard<std::mutex> lock(mutex);
    filtered.push_back(frame.index);
    kept[frame.index] = input;
    removed[frame.index] = heldout;
  });
  msf::LidarProjector projector(sequence.calibration(), config.projection);
  std::size_t checked = 0;
  pipeline.run(sequence, frames, [&](msf::FrameResult& r) {
    cv::Mat input_image, heldout_image;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      ASSERT_GT(removed[r.index].size(), 1000u) << "no held-out ring in frame " << r.index;
      projector.projectToImage(kept[r.index], input_image);
      projector.projectToImage(removed[r.index], heldout_image);
    }
    // Step 1 saw exactly the input rings: no pixel of a held-out return that no input
    // return shares.
    EXPECT_EQ(cv::norm(r.lidar_sparse, input_image, cv::NORM_INF), 0.0) << "frame " << r.index;
    EXPECT_GT(cv::countNonZero((heldout_image > 0) & (input_image == 0)), 1000);
    EXPECT_EQ(cv::countNonZero((heldout_image > 0) & (input_image == 0) & (r.lidar_sparse > 0)), 0);
    ++checked;
  });
  EXPECT_EQ(filtered, frames); // once per frame, in order
  EXPECT_EQ(checked, frames.size());
}

TEST_F(PipelineTest, TheFrameFilterChangesEachFrameBeforeAnyStageSeesIt) { checkTheFilterComesFirst(dataset()); }

TEST(FrameFilter, NoHeldOutReturnOfARealKittiScanReachesThePipeline) {
  MSF_REQUIRE_KITTI();
  checkTheFilterComesFirst(msf::test::kittiDir() + "/odometry/sequences/04");
}

/// With earlier scans carried into the view, under a ring hold-out: every scan the history holds
/// is a frame's input rings, none of its held-out returns, whichever way the poses come (the
/// dataset's, or the odometry's, tracked before steps 1-2); and the earlier scans add returns.
void checkNoHeldOutReturnIsCarried(msf::Reconstructor::PoseMode poses) {
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  const auto frames = sequence.indices(msf::FrameRange::parse("0:3"));
  msf::PipelineConfig config;
  config.accumulation.scans = 2;
  msf::Reconstructor::Options options;
  options.poses = poses;
  options.keep_sparse = true;
  msf::Reconstructor pipeline(sequence.calibration(), config, options);
  std::mutex mutex;
  std::map<std::size_t, pcl::PointCloud<pcl::PointXYZI>> removed;
  pipeline.setFrameFilter([&](msf::Frame& frame) {
    pcl::PointCloud<pcl::PointXYZI> input, heldout;
    msf::splitRings(*frame.scan, msf::RingSplitConfig{}, input, heldout);
    *frame.scan = input;
    const std::lock_guard<std::mutex> lock(mutex);
    removed[frame.index] = heldout;
  });
  std::size_t denser = 0;
  pipeline.run(sequence, frames, [&](msf::FrameResult& r) {
    // The LiDAR depth has real returns (distance 0) beyond the frame's own projected ones.
    const int own = cv::countNonZero(r.lidar_sparse > 0);
    const int real = cv::countNonZero(r.lidar_distance == 0.f);
    denser += r.index > 0 && real > own + 1000;
  });
  EXPECT_EQ(denser, frames.size() - 1);
  const msf::ScanHistory& history = pipeline.scanHistory();
  ASSERT_EQ(history.size(), 2u);
  for (std::size_t age = 1; age <= history.size(); ++age) {
    const std::size_t frame = frames.back() + 1 - age;
    std::set<std::array<float, 3>> heldout;
    for (const auto& p : removed[frame])
      heldout.insert({p.x, p.y, p.z});
    ASSERT_GT(heldout.size(), 1000u);
    std::size_t carried = 0;
    for (const auto& p : history.scan(age - 1))
      carried += heldout.count({p.x, p.y, p.z});
    EXPECT_EQ(carried, 0u) << "held-out returns of frame " << frame << " among the earlier scans";
    EXPECT_GT(history.scan(age - 1).size(), 10000u);
  }
}

TEST(EarlierScans, NoHeldOutRingIsCarriedWithTheDatasetsPoses) {
  MSF_REQUIRE_KITTI();
  checkNoHeldOutReturnIsCarried(msf::Reconstructor::PoseMode::Given);
}

TEST(EarlierScans, NoHeldOutRingIsCarriedWithTheOdometrysPoses) {
  MSF_REQUIRE_KITTI();
  checkNoHeldOutReturnIsCarried(msf::Reconstructor::PoseMode::Odometry);
}

/// A frame whose fused depth is `width` x `height` of `depth` weighing `weight`, its colour
/// (10, 20, 30), its camera of focal 100 px centred.
msf::FrameResult fusedFrame(const std::string& name, int width, int height, float depth, float weight) {
  msf::FrameResult r;
  r.name = name;
  r.fused.depth = cv::Mat(height, width, CV_32FC1, cv::Scalar(depth));
  r.fused.weight = cv::Mat(height, width, CV_32FC1, cv::Scalar(weight));
  r.fused.color = cv::Mat(height, width, CV_8UC3, cv::Scalar(10, 20, 30));
  r.fused.camera.fx = r.fused.camera.fy = 100.f;
  r.fused.camera.cx = 0.5f * static_cast<float>(width - 1), r.fused.camera.cy = 0.5f * static_cast<float>(height - 1);
  r.fused.camera.width = width, r.fused.camera.height = height;
  return r;
}

TEST(SourceDepthFrame, TakesTheSourcesDepthTheFusedColourAndTheFusionsWeights) {
  msf::FrameResult r = fusedFrame("000007", 3, 2, 4.f, 3.f);
  r.lidar_depth = (cv::Mat_<float>(2, 3) << 5.f, 0.f, std::nanf(""), 5.f, 5.f, -1.f);
  r.lidar_distance = (cv::Mat_<float>(2, 3) << 0.f, 1.f, 1.f, 0.f, 10.f, 1.f);
  r.stereo_depth = (cv::Mat_<float>(2, 3) << 0.f, 6.f, 12.f, 0.f, 0.f, 9.f);
  r.stereo_confidence = (cv::Mat_<float>(2, 3) << 1.f, 1.f, 1.f, 1.f, 1.f, 0.f);
  const msf::DepthFusionConfig fusion;
  const double fb = 386.0;

  const msf::DepthFrame lidar = msf::sourceDepthFrame(r, msf::DepthSource::Lidar, fusion, fb);
  EXPECT_EQ(lidar.depth.data, r.lidar_depth.data);
  EXPECT_EQ(lidar.color.data, r.fused.color.data);
  EXPECT_EQ(lidar.camera.fx, 100.f);
  // No depth, no weight; a real return outweighs an interpolated pixel 10 px from one.
  EXPECT_EQ(lidar.weight.at<float>(0, 1), 0.f);
  EXPECT_EQ(lidar.weight.at<float>(0, 2), 0.f);
  EXPECT_EQ(lidar.weight.at<float>(1, 2), 0.f);
  EXPECT_GT(lidar.weight.at<float>(1, 0), lidar.weight.at<float>(1, 1));
  EXPECT_GT(lidar.weight.at<float>(1, 1), 0.f);

  const msf::DepthFrame stereo = msf::sourceDepthFrame(r, msf::DepthSource::Stereo, fusion, fb);
  EXPECT_EQ(stereo.depth.data, r.stereo_depth.data);
  // The fusion's weight of a stereo-only pixel: 1 / sigma_z^2, sigma_z = z^2 sigma_d / (f B).
  const float sigma_z = 6.f * 6.f * fusion.stereo_sigma_min_px / static_cast<float>(fb);
  EXPECT_NEAR(stereo.weight.at<float>(0, 1), 1.f / (sigma_z * sigma_z), 1e-3f);
  EXPECT_NEAR(stereo.weight.at<float>(0, 2), stereo.weight.at<float>(0, 1) / 16.f, 1e-3f); // twice as far
  EXPECT_LT(stereo.weight.at<float>(1, 2), stereo.weight.at<float>(0, 1));                  // confidence 0
  EXPECT_EQ(stereo.weight.at<float>(0, 0), 0.f);

  r.stereo_depth.release();
  try {
    msf::sourceDepthFrame(r, msf::DepthSource::Stereo, fusion, fb);
    ADD_FAILURE() << "a frame without stereo depth was accepted";
  } catch (const msf::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 000007 has no stereo depth"), std::string::npos) << e.what();
  }
  EXPECT_THROW(msf::sourceDepthFrame(r, msf::DepthSource::Lidar, fusion, 0.0), msf::InvalidInputError);
}

TEST(FusedDepthFrame, TheFusedImageInTheLidarsCanvas) {
  // A 4x2 image in a canvas grown by 1 pixel: the margin takes the LiDAR's depth and weight,
  // the image its fused depth and weight, the colours of the image's border repeated.
  msf::FrameResult r = fusedFrame("000003", 4, 2, 7.f, 50.f);
  const msf::DepthFusionConfig fusion;
  const double fb = 386.0;
  // Without a canvas: the fused frame as it is.
  EXPECT_EQ(msf::fusedDepthFrame(r, fusion, fb).depth.data, r.fused.depth.data);

  r.lidar_canvas_depth = cv::Mat(4, 6, CV_32FC1, cv::Scalar(9.f));
  r.lidar_canvas_distance = cv::Mat(4, 6, CV_32FC1, cv::Scalar(0.f));
  r.lidar_canvas_camera = r.fused.camera;
  r.lidar_canvas_camera.cx += 1.f, r.lidar_canvas_camera.cy += 1.f;
  r.lidar_canvas_camera.width = 6, r.lidar_canvas_camera.height = 4;
  const msf::DepthFrame f = msf::fusedDepthFrame(r, fusion, fb);
  ASSERT_EQ(f.depth.size(), cv::Size(6, 4));
  EXPECT_EQ(f.camera.cx, 2.5f);
  EXPECT_EQ(f.depth.at<float>(0, 0), 9.f);  // margin: the LiDAR
  EXPECT_EQ(f.depth.at<float>(1, 1), 7.f);  // image: the fused depth
  EXPECT_EQ(f.weight.at<float>(1, 1), 50.f);
  // A real return in the margin weighs the LiDAR's range noise.
  EXPECT_NEAR(f.weight.at<float>(3, 5), 1.f / (fusion.lidar_range_sigma_m * fusion.lidar_range_sigma_m), 1e-2f);
  EXPECT_EQ(f.color.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 20, 30));
  f.validate();
  // The LiDAR alone lives on the canvas too.
  r.lidar_depth = cv::Mat(2, 4, CV_32FC1, cv::Scalar(9.f));
  r.lidar_distance = cv::Mat(2, 4, CV_32FC1, cv::Scalar(0.f));
  EXPECT_EQ(msf::sourceDepthFrame(r, msf::DepthSource::Lidar, fusion, fb).depth.size(), cv::Size(6, 4));
  // A canvas that cannot hold the image is an error naming the frame.
  r.lidar_canvas_distance = cv::Mat(3, 6, CV_32FC1, cv::Scalar(0.f));
  try {
    msf::fusedDepthFrame(r, fusion, fb);
    ADD_FAILURE() << "a bad canvas was accepted";
  } catch (const msf::InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 000003's LiDAR canvas"), std::string::npos) << e.what();
  }
}

} // namespace
