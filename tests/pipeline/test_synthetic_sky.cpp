// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The synthetic street under KITTI's overexposed sky (synthetic.sky kitti): SGBM smears the
// crowns' disparity over the clipped sky as on KITTI, the map hangs it as sheets without
// fusion.clear_sky, and none with it.
#include <msf/io/sequence.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/synthetic_scoring.h>
#include <msf/synthetic/synthetic_generator.h>

#include <test_support.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <numeric>

namespace {

/// The true sky the run's mesh covers with sheets (surface off the true surface).
msf::SkyCoverage sheetsOverTheTrueSky(const msf::Sequence& sequence, bool clear_sky) {
  msf::PipelineConfig config;
  config.fusion.clear_sky = clear_sky;
  msf::Reconstructor engine(sequence.calibration(), config);
  msf::SyntheticScoring truth(sequence.groundTruthDir(), true, config.volume.voxel_size_m);
  engine.setFrameFilter([&](msf::Frame& frame) { truth.addScan(frame); });
  std::vector<std::size_t> frames(sequence.size());
  std::iota(frames.begin(), frames.end(), 0);
  engine.run(sequence, frames, [&](msf::FrameResult& r) {
    truth.addFrame(r, truth.depth(r.name), sequence.calibration(), config.integrator.max_depth_m);
  });
  msf::MeshViewScoring views;
  msf::SyntheticScoring::TrueSky sky;
  truth.addTrueSkyViews(views, sky);
  views.score(engine.mesh());
  const msf::SkyCoverage sheets = sky.sheets.coverage();
  std::printf("  clear_sky %d: %.4f of the true sky covered by sheets (all cover %.4f), worst frame %.4f\n", clear_sky,
              sheets.share, sky.all.coverage().share, sheets.worst_share);
  return sheets;
}

} // namespace

TEST(SyntheticSky, TheKittiSkyHangsSheetsWithoutTheClearSkyAndNoneWithIt) {
  const msf::test::TempDir dir;
  // Frames 11-19 of the street of msf_synth -sky kitti -frames 20, where crowns stand against the sky.
  msf::synthetic::SyntheticConfig config;
  config.sky = "kitti";
  config.street_length_m = 19.0;
  config.start_m = 11.0;
  config.frames = 9;
  msf::synthetic::SyntheticGenerator(config).writeDataset(dir.path());
  const msf::Sequence sequence(dir.path());
  const msf::SkyCoverage without = sheetsOverTheTrueSky(sequence, false);
  const msf::SkyCoverage with = sheetsOverTheTrueSky(sequence, true);
  EXPECT_EQ(without.frames, 9u);
  EXPECT_EQ(with.sky_pixels, without.sky_pixels);
  EXPECT_GT(without.sky_pixels, 9u * 25000); // a wide sky over low houses
  EXPECT_GT(without.share, 0.012);
  EXPECT_LT(with.share, 0.005);
  EXPECT_LT(with.share, without.share / 4);
}
