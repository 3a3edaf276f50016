// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_kitti2bag: a dataset's frames (a KITTI odometry sequence, a raw drive, a synthetic
// sequence) to a ROS 1 bag in kitti2bag's layout, what msf_reconstruct file.bag and the node's
// launch file read.
#include <msf/common/exceptions.h>
#include <msf/common/stop_signals.h>
#include <msf/common/tool.h>
#include <msf/datasets/open_dataset.h>
#include <msf/ros/bag_writer.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cstdio>
#include <unistd.h>

using namespace pcl::console;

int main(int argc, char** argv) {
  std::string output, frames_text = "0:";
  msf::KittiBagOptions options;
  msf::tool::CommandLine cli(
      "msf_kitti2bag", "DATASET_DIR -o file.bag [options]",
      "Writes the frames of a KITTI odometry sequence, a KITTI raw drive or a synthetic sequence (msf_synth) into a "
      "ROS 1 bag in kitti2bag's layout: the scan on /kitti/velo/pointcloud (PointCloud2: x y z intensity), the "
      "grey pair and the colour left camera on /kitti/camera_{gray_left,gray_right,color_left}/{image_raw,"
      "camera_info} (CameraInfo's P: the calibration's P0, P1, P2), the LiDAR extrinsic and the cameras' places on "
      "/tf_static, the poses on /tf (camera_init -> camera_gray_left). All messages of a frame carry its stamp: the "
      "start time plus the frame's time in the dataset.");
  cli.value("-o", "FILE", output, "the bag to write")
      .value("-frames", "a:b", frames_text, "frame range, inclusive (default: all)")
      .value("-start_time", "S", options.start_time_s,
             "stamp of the dataset's time 0, in seconds since the epoch (default {default}; kitti2bag takes the "
             "time of conversion)")
      .value("-compression", "C", options.compression, "none (default, kitti2bag's), lz4 or bz2")
      .value("-images", "CODEC", options.images,
             "raw (default, kitti2bag's Image on image_raw), or png (lossless) or jpeg: CompressedImage on "
             "image_raw/compressed, as a rig that records compressed images writes them")
      .overwriteOption(options.overwrite);
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) {
    if (positional.size() != 1)
      throw msf::InvalidInputError("expected one DATASET_DIR, got " + std::to_string(positional.size()) +
                                   " positional arguments (see -h)");
    if (output.empty())
      throw msf::InvalidInputError("no output bag: give -o file.bag");
    msf::requireKittiBagOptions(options);
    msf::tool::requireNewOutputs({output}, options.overwrite);
    msf::tool::installStopSignals({"msf_kitti2bag: stopping; the bag is not written"});
    const auto source = msf::openDataset(positional.front());
    const std::vector<std::size_t> frames = source->indices(msf::FrameRange::parse(frames_text));
    print_highlight("Writing ");
    print_value("%zu", frames.size());
    print_info(" frames of ");
    print_value("%s", source->description().c_str());
    print_info(" to ");
    print_value("%s ", output.c_str());
    TicToc tt;
    tt.tic();
    const bool tty = ::isatty(STDOUT_FILENO);
    options.progress = [&](std::size_t done, std::size_t total) {
      if (msf::tool::stopFlag())
        throw msf::InvalidInputError("interrupted after " + std::to_string(done) + " frames: '" + output +
                                     "' is not written");
      if (tty)
        std::printf("\r  frame %zu/%zu ", done, total);
      std::fflush(stdout);
    };
    msf::writeKittiBag(*source, frames, output, options);
    if (tty)
      std::printf("\n");
    msf::tool::printDone(tt.toc(), frames.size(), "frames");
    return 0;
  });
}
