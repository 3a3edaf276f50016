// Writes a synthetic street in KITTI's odometry layout, with exact ground truth.
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/stop_signals.h>
#include <msf/common/tool.h>
#include <msf/synthetic/synthetic_generator.h>

#include <pcl/console/print.h>
#include <pcl/console/time.h>

#include <cstring>
#include <iostream>
#include <string>
#include <vector>


using namespace pcl::console;

namespace {

/// Throws when `option` was given with a value outside lo..hi.
void checkRange(const msf::tool::CommandLine& cli, const char* option, int value, int lo, int hi) {
  if (cli.given(option) && (value < lo || value > hi))
    throw msf::InvalidInputError(std::string("option ") + option + ": " + std::to_string(value) +
                                 " is out of range " + std::to_string(lo) + ".." + std::to_string(hi));
}

} // namespace

int main(int argc, char** argv) {
  msf::synthetic::SyntheticConfig config;
  std::string output;
  bool print_config = false;
  msf::tool::CommandLine cli(
      "msf_synth", "-o DIR [options]",
      "Renders a synthetic street with KITTI's sensor rig and writes it in KITTI's odometry layout with exact ground "
      "truth:\n"
      "  DIR/sequences/00/{image_0,image_1,image_2,image_3,velodyne}/, calib.txt, times.txt\n"
      "  DIR/poses/00.txt\n"
      "  DIR/gt/{depth_0,disp_0,obj_map_0,moving_0}/NNNNNN.png, moving_objects.txt, scene.ply,\n"
      "    synthetic.yaml (scene.ply is the static world; moving_* are the driving cars)\n"
      "Every msf_* tool reads DIR (or DIR/sequences/00) as a sequence. Byte-identical for a seed.");
  cli.value("-o", "DIR", output, "output folder: absent, empty, or one msf_synth wrote before (replaced; anything else in it is refused)")
      .value("-config", "FILE", [&](const std::string& path) { msf::readConfigSection(path, config); },
             "YAML config; its `synthetic` section sets every key (see config/synthetic.yaml)")
      .value("-frames", "N", config.frames, "number of frames (default {default})")
      .value("-seed", "S", config.seed, "random seed, a whole number >= 0 (default {default})")
      .value("-scene", "NAME", config.scene, "scene to render: street (default)")
      .flag("-loop", config.loop,
            "drive out, turn round across the road and drive back in the other lane to the start (synthetic.loop): "
            "the way back revisits the street")
      .flag("-print_config", print_config, "print the configuration in effect");
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) {
    if (!positional.empty())
      throw msf::InvalidInputError("unexpected argument '" + positional.front() + "' (the output folder goes after -o)");
    checkRange(cli, "-frames", config.frames, 1, 999999);
    checkRange(cli, "-seed", config.seed, 0, 2147483647);
    if (config.scene != "street")
      throw msf::InvalidInputError("option -scene: unknown scene '" + config.scene + "' (known: street)");
    config.validate();
    if (output.empty())
      throw msf::InvalidInputError("no output folder: give -o DIR");
    if (print_config)
      msf::printConfig(std::cout, config);

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
    // A stop signal ends the run at the next frame, leaving no staging folder and OUT as it was.
    msf::tool::installStopSignals({"msf_synth: stopping after the frame under way; nothing is written"});
    generator.writeDataset(output, [&](std::size_t frame, double s, std::size_t points) {
      if (msf::tool::stopFlag())
        throw msf::InvalidInputError("interrupted at frame " + std::to_string(frame) + ": nothing was written to '" +
                                     output + "'");
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
