// Writes a synthetic street in KITTI's odometry layout, with exact ground truth.
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/tool.h>
#include <msf/synthetic/synthetic_generator.h>

#include <pcl/console/parse.h>
#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cstring>
#include <iostream>
#include <string>
#include <vector>

using namespace pcl::console;

namespace {

void printHelp(const char* name) {
  print_error("Syntax is: %s -o DIR [options]\n", name);
  print_info("  Renders a synthetic street with KITTI's sensor rig and writes it in KITTI's odometry\n"
             "  layout with exact ground truth:\n"
             "    DIR/sequences/00/{image_0,image_1,image_2,image_3,velodyne}/, calib.txt, times.txt\n"
             "    DIR/poses/00.txt\n"
             "    DIR/gt/{depth_0,disp_0,obj_map_0,moving_0}/NNNNNN.png, moving_objects.txt, scene.ply,\n"
             "      synthetic.yaml (scene.ply is the static world; moving_* are the driving cars)\n"
             "  Every msf_* tool reads DIR (or DIR/sequences/00) as a sequence. Byte-identical for a seed.\n");
  print_info("  where options are:\n");
  print_info("    -o DIR         output folder (absent, empty, or an earlier synthetic dataset, replaced)\n");
  print_info("    -frames N      number of frames (default 10)\n");
  print_info("    -seed S        random seed, a whole number >= 0 (default 1)\n");
  print_info("    -scene NAME    scene to render: street (default)\n");
  print_info("    -loop          drive out, turn round across the road and drive back in the other lane to\n"
             "                   the start (synthetic.loop): the way back revisits the street\n");
  print_info("    -config FILE   YAML config; its `synthetic` section sets every key (see config/synthetic.yaml)\n");
  print_info("    -print_config  print the configuration in effect\n");
}

/// The value of integer option `option` (strictly parsed), within lo..hi; `fallback` when absent.
int intOption(int argc, char** argv, const char* option, int fallback, int lo, int hi) {
  int value = fallback;
  if (msf::tool::parseArgument(argc, argv, option, value) >= 0 && (value < lo || value > hi))
    throw msf::InvalidInputError(std::string("option ") + option + ": " + std::to_string(value) +
                                 " is out of range " + std::to_string(lo) + ".." + std::to_string(hi));
  return value;
}

} // namespace

int main(int argc, char** argv) {
  return msf::tool::runWithHelp(argc, argv, "msf_synth", 2, printHelp, [&] {
    const std::vector<std::string> value_options{"-o", "-frames", "-seed", "-scene", "-config"};
    msf::tool::checkOptions(argc, argv, value_options, {"-print_config", "-loop"});
    const auto positional = msf::tool::positionalArguments(argc, argv, value_options);
    if (!positional.empty())
      throw msf::InvalidInputError("unexpected argument '" + positional.front() + "' (the output folder goes after -o)");

    msf::synthetic::SyntheticConfig config;
    std::string config_path, output;
    msf::tool::parseArgument(argc, argv, "-config", config_path);
    msf::tool::parseArgument(argc, argv, "-o", output);
    if (!config_path.empty())
      msf::readConfigSection(config_path, "synthetic", config);
    config.frames = intOption(argc, argv, "-frames", config.frames, 1, 999999);
    config.seed = intOption(argc, argv, "-seed", config.seed, 0, 2147483647);
    msf::tool::parseArgument(argc, argv, "-scene", config.scene);
    if (find_switch(argc, argv, "-loop"))
      config.loop = true;
    if (config.scene != "street")
      throw msf::InvalidInputError("option -scene: unknown scene '" + config.scene + "' (known: street)");
    config.validate();
    if (output.empty())
      throw msf::InvalidInputError("no output folder: give -o DIR");
    if (find_switch(argc, argv, "-print_config"))
      config.print(std::cout);

    TicToc tt;
    tt.tic();
    print_highlight("Building the street ");
    const msf::synthetic::SyntheticGenerator generator(config);
    print_info("[done, ");
    print_value("%g", tt.toc());
    print_info(" ms : ");
    print_value("%zu", generator.scene().primitives.size());
    print_info(" solids, ");
    print_value("%u", generator.scene().objectCount());
    print_info(" foreground objects, ");
    print_value("%zu", generator.scene().movers.size());
    print_info(" of them moving]\n");

    std::vector<double> seconds;
    tt.tic();
    print_highlight("Writing ");
    print_value("%d frames", config.frames);
    print_info(" to ");
    print_value("%s\n", output.c_str());
    generator.writeDataset(output, [&](std::size_t frame, double s, std::size_t points) {
      seconds.push_back(s);
      print_info("  frame %06zu ", frame);
      msf::tool::printDone(1000.0 * s, points);
    });
    print_info("Wrote ");
    print_value("%s", output.c_str());
    print_info(": %d frames, median ", config.frames);
    print_value("%.3f", msf::median(seconds));
    print_info(" s per frame, total ");
    print_value("%.1f", tt.toc() / 1000.0);
    print_info(" s\n");
    return 0;
  });
}
