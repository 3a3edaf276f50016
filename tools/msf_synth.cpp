// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Writes a synthetic street in KITTI's odometry layout, with exact ground truth.
#include <msf/pipeline/config_catalog.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/stop_signals.h>
#include <msf/common/tool.h>
#include <msf/io/rig_file.h>
#include <msf/synthetic/synthetic_generator.h>
#include <msf/synthetic/synthetic_rig.h>

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

/// -image_size, -focal and -baseline describe a pinhole pair: they ask for camera pinhole.
void requirePinholeFor(const msf::tool::CommandLine& cli, msf::synthetic::SyntheticConfig& config) {
  for (const char* option : {"-image_size", "-focal", "-baseline"}) {
    if (!cli.given(option))
      continue;
    if (cli.given("-camera") && config.camera != "pinhole")
      throw msf::InvalidInputError(std::string("option ") + option + " sets a pinhole camera, but -camera is '" +
                                   config.camera + "'");
    config.camera = "pinhole";
  }
}

/// The "Building the street" done line: what the scene holds.
void printStreet(const msf::synthetic::SyntheticGenerator& generator, double milliseconds) {
  print_info("[done, ");
  print_value("%g", milliseconds);
  print_info(" ms : ");
  print_value("%zu", generator.scene().primitives.size());
  print_info(" solids, ");
  print_value("%u", generator.scene().objectCount());
  print_info(" foreground objects, ");
  print_value("%zu", generator.scene().movers.size());
  print_info(" of them moving]\n");
}

/// Writes the dataset into `output`, a done line a frame; a stop signal ends it at the next
/// frame, leaving no staging folder and `output` as it was.
void writeFrames(const msf::synthetic::SyntheticGenerator& generator, int frames, const std::string& output) {
  std::vector<double> seconds;
  TicToc tt;
  tt.tic();
  print_highlight("Writing ");
  print_value("%d frames", frames);
  print_info(" to ");
  print_value("%s\n", output.c_str());
  msf::tool::installStopSignals({"msf_synth: stopping after the frame under way; nothing is written"});
  generator.writeDataset(output, [&](std::size_t frame, double s, std::size_t points) {
    if (msf::tool::stopFlag())
      throw msf::InvalidInputError("interrupted at frame " + std::to_string(frame) + ": nothing was written to '" +
                                   output + "'");
    seconds.push_back(s);
    print_info("  frame %06zu ", frame);
    msf::tool::printDone(1000.0 * s, points, "points");
  });
  print_info("Wrote ");
  print_value("%s", output.c_str());
  print_info(": %d frames, median ", frames);
  print_value("%.3f", msf::median(seconds));
  print_info(" s per frame, total ");
  print_value("%.1f", tt.toc() / 1000.0);
  print_info(" s\n");
}

} // namespace

// Longer than the other steps for its option table: one declaration an option.
int main(int argc, char** argv) {
  msf::synthetic::SyntheticConfig config;
  std::string output;
  bool print_config = false;
  msf::tool::CommandLine cli(
      "msf_synth", "-o DIR [options]",
      "Renders a synthetic street with KITTI's sensor rig (or another: -rig, -camera, -lidar) and writes it in "
      "KITTI's odometry layout with exact ground truth:\n"
      "  DIR/sequences/00/{image_0,image_1,image_2,image_3,velodyne}/, calib.txt, rig.yaml, times.txt\n"
      "  DIR/poses/00.txt\n"
      "  DIR/gt/{depth_0,disp_0,obj_map_0,moving_0}/NNNNNN.png, moving_objects.txt, scene.ply,\n"
      "    synthetic.yaml (scene.ply is the static world; moving_* are the driving cars),\n"
      "    poses.txt (with -ins_poses: the truth, poses/00.txt then being a GPS/INS's measurement)\n"
      "Every msf_* tool reads DIR (or DIR/sequences/00) as a sequence. Byte-identical for a seed.\n"
      "Several drives over one street: the same -seed and -street_m, and each its own -start_m, -reverse, -frames "
      "(e.g. msf_synth -o A -street_m 120 -frames 30; msf_synth -o B -street_m 120 -start_m 20 -frames 30; msf_synth "
      "-o C -street_m 120 -start_m 100 -reverse -frames 30).");
  cli.value("-o", "DIR", output, "output folder: absent, empty, or one msf_synth wrote before (replaced; anything else in it is refused)")
      .value("-config", "FILE", [&](const std::string& path) { msf::readConfigSection(path, config); },
             "YAML config; its `synthetic` section sets every key (see config/synthetic.yaml)")
      .value("-rig", "FILE",
             [&](const std::string& path) { msf::synthetic::applyRig(msf::loadRigFile(path), config); },
             "a rig file (README, \"Your own rig\"): its image size, focal length, principal point, baseline "
             "and, when it lists them, its LiDAR's beam_elevations_deg (the LiDAR is mounted as KITTI's)")
      .value("-camera", "NAME", config.camera,
             "kitti: KITTI's cameras, 1242x375 (default) | pinhole: a grey pair of -image_size, -focal, -baseline")
      .value("-image_size", "WxH",
             [&](const std::string& text) {
               const cv::Size size = msf::parseImageSize(text);
               config.image_width_px = size.width;
               config.image_height_px = size.height;
             },
             "pinhole image size (default 640x480)")
      .value("-focal", "PX", config.focal_px, "pinhole focal length in pixels (default {default})")
      .value("-baseline", "M", config.baseline_m, "pinhole baseline in metres (default {default})")
      .value("-lidar", "MODEL", config.lidar_model,
             "hdl64e: KITTI's 64 beams (default) | hdl32e: 32 beams, -30.67..+10.67 deg | beams: "
             "synthetic.lidar_beam_elevations_deg of -config")
      .value("-frames", "N", config.frames, "number of frames (default {default})")
      .value("-seed", "S", config.seed, "random seed, a whole number >= 0 (default {default})")
      .value("-scene", "NAME", config.scene, "scene to render: street (default)")
      .value("-sky", "LOOK", config.sky,
             "pale: a smooth pale blue (default) | kitti: KITTI's overexposed sky, clipped to a flat white near the "
             "horizon and in soft clouds, where SGBM smears the crowns' disparity (synthetic.sky)")
      .flag("-loop", config.loop,
            "drive out, turn round across the road and drive back in the other lane to the start (synthetic.loop): "
            "the way back revisits the street")
      .flag("-ins_poses", config.ins_poses,
            "write the poses as a GPS/INS measures them (synthetic.ins_poses): poses/00.txt with a heading that "
            "drifts by synthetic.ins_heading_drift_deg_per_s and a position that wanders by "
            "synthetic.ins_position_error_m, gt/poses.txt the truth; msf_reconstruct refines them by default")
      .value("-start_m", "S", config.start_m,
             "the drive starts S metres along the street (synthetic.start_m, default {default}); its poses are in the "
             "street's world, where drives of the same -seed and -street_m meet")
      .flag("-reverse", config.reverse,
            "the drive heads back along the street in the other lane, from -start_m towards the street's start "
            "(synthetic.reverse)")
      .value("-street_m", "L", config.street_length_m,
             "the street's length (synthetic.street_length_m; default {default}: as far as the drive goes): drives "
             "given the same -seed and -street_m share one static world, gt/scene.ply included")
      .flag("-print_config", print_config, "print the configuration in effect");
  return cli.run(argc, argv, 1, [&](const msf::tool::Arguments& positional) {
    if (!positional.empty())
      throw msf::InvalidInputError("unexpected argument '" + positional.front() + "' (the output folder goes after -o)");
    checkRange(cli, "-frames", config.frames, 1, 999999);
    checkRange(cli, "-seed", config.seed, 0, 2147483647);
    if (config.scene != "street")
      throw msf::InvalidInputError("option -scene: unknown scene '" + config.scene + "' (known: street)");
    if (cli.given("-sky") && config.sky != "pale" && config.sky != "kitti")
      throw msf::InvalidInputError("option -sky: unknown sky '" + config.sky + "' (known: pale, kitti)");
    requirePinholeFor(cli, config);
    config.validate();
    if (output.empty())
      throw msf::InvalidInputError("no output folder: give -o DIR");
    if (print_config)
      msf::printConfig(std::cout, config);

    TicToc tt;
    tt.tic();
    print_highlight("Building the street ");
    const msf::synthetic::SyntheticGenerator generator(config);
    printStreet(generator, tt.toc());
    writeFrames(generator, config.frames, output);
    return 0;
  });
}
