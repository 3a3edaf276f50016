// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Converts KITTI Velodyne .bin scans to PointXYZI .pcd clouds, in file order.
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/common/tool.h>
#include <msf/io/cloud_io.h>
#include <msf/io/velodyne_io.h>

#include <pcl/io/pcd_io.h>

#include <pcl/console/time.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <filesystem>
#include <vector>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

std::size_t convert(const std::string& in, const std::string& out, bool ascii) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  TicToc tt;
  tt.tic();
  print_highlight("Loading ");
  print_value("%s ", in.c_str());
  const auto stats = msf::loadVelodyneBin(in, cloud);
  msf::tool::printDone(tt.toc(), cloud.size(), "points");
  if (stats.dropped_nonfinite > 0)
    print_warn("dropped %zu of %zu records with non-finite values\n", stats.dropped_nonfinite, stats.records);

  tt.tic();
  print_highlight("Saving ");
  print_value("%s ", out.c_str());
  if (ascii) {
    if (cloud.empty())
      throw msf::InvalidInputError("cannot write '" + out + "': the scan has no finite point");
    msf::writeThroughPipeAtomically(out, [&](const std::string& sink) {
      if (pcl::PCDWriter().writeASCII(sink, cloud) != 0)
        throw msf::IOError("cannot write cloud '" + out + "'");
    });
  } else {
    msf::saveCloud(out, cloud);
  }
  msf::tool::printDone(tt.toc(), cloud.size(), "points");
  return cloud.size();
}

} // namespace

int main(int argc, char** argv) {
  std::string input_dir, output_dir;
  bool ascii = false, overwrite = false;
  msf::tool::CommandLine cli(
      "msf_kitti2pcd", "<scan.bin> <out.pcd> [options]\n-input_dir DIR -output_dir DIR [options]",
      "Reads KITTI Velodyne scans (float32 x, y, z, reflectance) into pcl::PointXYZI clouds, in file order (which "
      "carries the ring structure). Records with NaN or Inf are dropped.");
  cli.value("-input_dir", "DIR", input_dir, "convert every *.bin of DIR ...")
      .value("-output_dir", "DIR", output_dir, "... into DIR/<name>.pcd (DIR: absent, empty, or written by an earlier batch, which it replaces)")
      .flag("-ascii", ascii, "write ASCII .pcd instead of binary compressed")
      .overwriteOption(overwrite);
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& files) {
    if (!input_dir.empty() || !output_dir.empty()) {
      if (input_dir.empty() || output_dir.empty())
        throw msf::InvalidInputError("batch mode needs both -input_dir and -output_dir");
      std::vector<fs::path> scans;
      for (const std::string& scan : msf::filesIn(input_dir, {".bin"}, "input folder"))
        scans.emplace_back(scan);
      // The batch is a unit: a truncated scan is found before anything is written, and the
      // clouds go into OUT as a whole (an OutputFolder) or not at all.
      for (const auto& scan : scans)
        if (fs::file_size(scan) % 16 != 0)
          throw msf::IOError("scan '" + scan.string() + "' has " + std::to_string(fs::file_size(scan)) +
                             " bytes, not a multiple of 16 (float32 x, y, z, reflectance): truncated or not a "
                             "KITTI .bin; nothing was converted");
      msf::OutputFolder output(output_dir, "msf_kitti2pcd", {input_dir});
      for (const auto& scan : scans)
        convert(scan.string(), (fs::path(output.dir()) / (scan.stem().string() + ".pcd")).string(), ascii);
      output.commit();
      print_info("converted %zu scans\n", scans.size());
      return 0;
    }

    if (files.size() != 2)
      throw msf::InvalidInputError("expected <scan.bin> <out.pcd> (see -h)");
    if (msf::fileExtension(files[1]) != ".pcd")
      throw msf::InvalidInputError("output '" + files[1] + "' must end in .pcd");
    msf::tool::requireNewOutputs({files[1]}, overwrite);
    convert(files[0], files[1], ascii);
    return 0;
  });
}
