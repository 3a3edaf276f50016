// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_convert: any dataset the project reads into the generic layout (a rig file, lidar/,
// left/, right/, color/, timestamps.txt, poses.txt): what a user's own recording looks like.
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/common/stop_signals.h>
#include <msf/common/tool.h>
#include <msf/datasets/open_dataset.h>
#include <msf/io/image_io.h>
#include <msf/io/poses.h>
#include <msf/io/rig_file.h>
#include <msf/io/velodyne_io.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

void writeFrame(const msf::Frame& frame, const std::string& name, const fs::path& out) {
  msf::saveVelodyneBin((out / "lidar" / (name + ".bin")).string(), *frame.scan);
  msf::writeImage((out / "left" / (name + ".png")).string(), frame.left);
  msf::writeImage((out / "right" / (name + ".png")).string(), frame.right);
  if (!frame.color.empty())
    msf::writeImage((out / "color" / (name + ".png")).string(), frame.color);
}

void writeTimes(const std::vector<double>& times, const fs::path& path) {
  msf::writeAtomically(path.string(), [&](const std::string& tmp) {
    std::FILE* file = std::fopen(tmp.c_str(), "w");
    if (!file)
      throw msf::IOError("cannot write '" + path.string() + "'");
    bool ok = true;
    for (double t : times)
      ok = ok && std::fprintf(file, "%.9f\n", t) > 0;
    ok = std::fclose(file) == 0 && ok;
    if (!ok)
      throw msf::IOError("cannot write '" + path.string() + "' to the end");
  });
}

} // namespace

int main(int argc, char** argv) {
  std::string frames_text = "0:";
  msf::tool::CommandLine cli(
      "msf_convert", "DATASET OUT_DIR [options]",
      "Writes a dataset the project reads (a KITTI odometry sequence or raw drive, a synthetic sequence, a folder of "
      "the generic layout, a ROS 1 bag of kitti2bag's topics or those named below) into the generic layout, the one a user makes from their own recording:\n"
      "  OUT_DIR/rig.yaml, lidar/NNNNNN.bin, left/ right/ color/NNNNNN.png, timestamps.txt, poses.txt\n"
      "Frames are numbered from 000000 in the order converted; line i of the text files is frame i.");
  msf::DatasetOptions reader;
  cli.value("-frames", "a:b", frames_text, "frame range, inclusive (default: all)");
  msf::addDatasetOptions(cli, reader);
  return cli.run(argc, argv, 2, [&](const msf::tool::Arguments& positional) {
    if (positional.size() != 2)
      throw msf::InvalidInputError("expected DATASET OUT_DIR (see -h)");
    const auto source = msf::openDataset(positional[0], reader);
    const std::vector<std::size_t> frames = source->indices(msf::FrameRange::parse(frames_text));
    msf::tool::installStopSignals({"msf_convert: stopping after the frame under way; nothing is written"});
    msf::OutputFolder output(positional[1], "msf_convert", {positional[0], reader.rig});
    const fs::path out = output.dir();
    for (const char* sub : {"lidar", "left", "right"})
      fs::create_directory(out / sub);
    if (source->hasColor())
      fs::create_directory(out / "color");
    msf::saveRigFile(source->calibration(), (out / "rig.yaml").string());
    // Frame k of the output is the k-th frame converted: its lines are k.
    std::vector<double> times;
    msf::PoseList poses;
    TicToc tt;
    tt.tic();
    print_highlight("Converting ");
    print_value("%zu", frames.size());
    print_info(" frames of %s into %s ", source->description().c_str(), positional[1].c_str());
    for (std::size_t k = 0; k < frames.size(); ++k) {
      if (msf::tool::stopFlag())
        throw msf::InvalidInputError("interrupted: nothing was written to '" + positional[1] + "'");
      const msf::Frame frame = source->load(frames[k]);
      char name[32];
      std::snprintf(name, sizeof name, "%06zu", k);
      writeFrame(frame, name, out);
      times.push_back(frame.timestamp);
      if (frame.has_pose)
        poses.push_back(frame.T_world_cam0);
    }
    writeTimes(times, out / "timestamps.txt");
    if (poses.size() == frames.size())
      msf::saveOdometryPoses((out / "poses.txt").string(), poses);
    output.commit();
    msf::tool::printDone(tt.toc(), frames.size(), "frames");
    return 0;
  });
}
