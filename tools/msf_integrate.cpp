// msf_integrate: fuses organized depth clouds (camera frame, NaN = no depth) seen from known
// poses into a sparse TSDF volume (paper §III-C, eq. 7), saved as a .pcd voxel cloud.
#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/tool.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>
#include <msf/reconstruction/tsdf_integrator.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <pcl/console/time.h>
#include <pcl/console/parse.h>
#include <pcl/console/print.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace pcl::console;

namespace {

const std::vector<std::string> kValueOptions = {"-poses", "-o", "-voxel", "-trunc", "-max_memory", "-lambda", "-sweeps", "-weighting",
                                                "-max_weight", "-max_depth", "-calib", "-input_dir", "-frames", "-config"};
const std::vector<std::string> kSwitches = {"-carving", "-no_carving", "-print_config"};

void printHelp(const char* name) {
  print_error("Syntax is: %s <depth_cloud.pcd>... -poses poses.txt -o volume.pcd [options]\n", name);
  print_info("  Integrates organized depth clouds (rectified camera 0 frame, NaN where there is no depth)\n"
             "  into a sparse TSDF volume, the i-th cloud seen from the i-th pose (T_world_cam, KITTI\n"
             "  odometry format). A cloud's rgb colours the voxels; a 'weight' field (1/sigma^2 of the depth,\n"
             "  msf_fuse's) is used with -weighting per_pixel. Options:\n");
  print_info("    -input_dir DIR      also every .pcd of DIR, in name order\n");
  print_info("    -frames a:b         the poses of these lines (0-based) only, when the file has more\n");
  print_info("    -calib PATH         camera intrinsics (KITTI calib.txt, raw folder or YAML); default:\n"
             "                        recovered from each cloud's points and pixels\n");
  print_info("    -voxel M            voxel size in metres (default "); print_value("0.1"); print_info(")\n");
  print_info("    -trunc M            truncation distance in metres (default "); print_value("0.3"); print_info(")\n");
  print_info("    -lambda L           eq. 7 regularization (default "); print_value("0"); print_info(", the paper's KITTI value is 5)\n");
  print_info("    -max_memory MB      memory budget of the volume (tsdf_volume.max_memory_mb; default 0: 3/4 of RAM)\n");
  print_info("    -sweeps N           Gauss-Seidel sweeps per frame (default "); print_value("1"); print_info(")\n");
  const msf::TsdfIntegrator::Config defaults; // the help says what the code does
  print_info("    -weighting W        constant | inverse_square | per_pixel (default ");
  print_value("%s", msf::toString(defaults.weighting)); print_info(")\n");
  print_info("    -max_weight W       weight (m^-2) at which a voxel saturates (default ");
  print_value("%s", msf::configValue(defaults.max_weight).c_str()); print_info(")\n");
  print_info("    -max_depth M        ignore depth beyond M metres (default ");
  print_value("%s", msf::configValue(defaults.max_depth_m).c_str()); print_info(")\n");
  print_info("    -carving, -no_carving  space carving on or off: voxels seen in front of the surface become free\n"
             "                        (default ");
  print_value("%s", defaults.space_carving ? "on" : "off"); print_info("; tsdf_integrator.space_carving)\n");
  print_info("    -config FILE        YAML with sections tsdf_volume and tsdf_integrator; flags override it\n");
  print_info("    -print_config       print the configuration in use\n");
}

std::vector<std::string> inputClouds(int argc, char** argv) {
  std::vector<std::string> files;
  for (const auto& a : msf::tool::positionalArguments(argc, argv, kValueOptions))
    files.push_back(a);
  std::string dir;
  if (msf::tool::parseArgument(argc, argv, "-input_dir", dir) >= 0) {
    msf::requireDirectory(dir, "input folder");
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && msf::fileExtension(e.path().string()) == ".pcd")
        found.push_back(e.path().string());
    std::sort(found.begin(), found.end());
    if (found.empty())
      throw msf::IOError("input folder '" + dir + "' has no .pcd file");
    files.insert(files.end(), found.begin(), found.end());
  }
  return files;
}

int run(int argc, char** argv) {
  msf::tool::checkOptions(argc, argv, kValueOptions, kSwitches);
  const std::vector<std::string> clouds = inputClouds(argc, argv);
  std::string poses_path, output;
  msf::tool::parseArgument(argc, argv, "-poses", poses_path);
  msf::tool::parseArgument(argc, argv, "-o", output);
  if (clouds.empty() || poses_path.empty() || output.empty()) {
    printHelp(argv[0]);
    throw msf::InvalidInputError("need depth clouds, -poses and -o");
  }
  if (msf::fileExtension(output) != ".pcd")
    throw msf::InvalidInputError("output '" + output + "' must be a .pcd file");

  msf::TsdfVolume::Config volume_config;
  msf::TsdfIntegrator::Config config;
  std::string config_path;
  if (msf::tool::parseArgument(argc, argv, "-config", config_path) >= 0) {
    const msf::ConfigFile file(config_path);
    volume_config.read(file.section("tsdf_volume"));
    config.read(file.section("tsdf_integrator"));
    file.rejectUnknownKeys();
  }
  msf::tool::parseArgument(argc, argv, "-voxel", volume_config.voxel_size_m);
  msf::tool::parseArgument(argc, argv, "-trunc", volume_config.truncation_m);
  msf::tool::parseArgument(argc, argv, "-max_memory", volume_config.max_memory_mb);
  msf::tool::parseArgument(argc, argv, "-lambda", config.lambda);
  msf::tool::parseArgument(argc, argv, "-sweeps", config.sweeps);
  msf::tool::parseArgument(argc, argv, "-max_weight", config.max_weight);
  msf::tool::parseArgument(argc, argv, "-max_depth", config.max_depth_m);
  std::string weighting;
  if (msf::tool::parseArgument(argc, argv, "-weighting", weighting) >= 0)
    config.weighting = msf::parseWeighting(weighting);
  if (find_switch(argc, argv, "-carving") && find_switch(argc, argv, "-no_carving"))
    throw msf::InvalidInputError("-carving and -no_carving together: choose one");
  if (find_switch(argc, argv, "-carving"))
    config.space_carving = true;
  if (find_switch(argc, argv, "-no_carving"))
    config.space_carving = false;
  msf::TsdfVolume volume(volume_config); // validates voxel size and truncation
  msf::TsdfIntegrator integrator(volume, config);
  if (find_switch(argc, argv, "-print_config")) {
    volume_config.print(std::cout);
    config.print(std::cout);
  }

  msf::PoseList poses = msf::loadOdometryPoses(poses_path);
  std::string frames;
  if (msf::tool::parseArgument(argc, argv, "-frames", frames) >= 0) {
    const msf::FrameRange range = msf::FrameRange::parse(frames);
    const int last = range.last < 0 ? static_cast<int>(poses.size()) - 1 : range.last;
    if (range.first >= static_cast<int>(poses.size()) || last >= static_cast<int>(poses.size()))
      throw msf::InvalidInputError("frames '" + frames + "' is beyond the " + std::to_string(poses.size()) +
                                   " poses of '" + poses_path + "'");
    poses = msf::PoseList(poses.begin() + range.first, poses.begin() + last + 1);
  }
  if (poses.size() != clouds.size())
    throw msf::InvalidInputError(std::to_string(clouds.size()) + " depth clouds but " + std::to_string(poses.size()) +
                                 " poses in '" + poses_path + "' (one pose per cloud; -frames a:b selects poses)");

  msf::PinholeCamera camera;
  std::string calib;
  if (msf::tool::parseArgument(argc, argv, "-calib", calib) >= 0)
    camera = msf::PinholeCamera::fromCalibration(msf::loadCalibration(calib));

  pcl::console::TicToc tt;
  double integrate_ms = 0;
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    print_highlight("Integrating ");
    print_value("%s ", clouds[i].c_str());
    tt.tic();
    pcl::PCLPointCloud2 blob;
    msf::loadCloudBlob(clouds[i], blob);
    const msf::DepthFrame frame = msf::toDepthFrame(blob, camera.valid() ? &camera : nullptr, "cloud '" + clouds[i] + "'");
    integrator.integrate(frame, poses[i]);
    integrate_ms += integrator.lastStats().allocate_ms + integrator.lastStats().update_ms +
                    integrator.lastStats().regularize_ms;
    msf::tool::printDone(tt.toc(), integrator.lastStats().voxels_updated);
  }
  print_info("Volume: ");
  print_value("%zu", volume.numBlocks());
  print_info(" blocks, ");
  print_value("%zu", volume.numObservedVoxels());
  print_info(" observed voxels, ");
  print_value("%.1f", static_cast<double>(volume.memoryBytes()) / (1024.0 * 1024.0));
  print_info(" MiB; integration ");
  print_value("%.1f", integrate_ms / static_cast<double>(clouds.size()));
  print_info(" ms per frame\n");

  print_highlight("Saving ");
  print_value("%s ", output.c_str());
  tt.tic();
  volume.save(output);
  msf::tool::printDone(tt.toc(), volume.numObservedVoxels());
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_integrate", 2, printHelp, [&] { return run(argc, argv); });
}
