// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/synthetic/synthetic_config.h>

#include "test_support.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace {

using msf::synthetic::SyntheticConfig;

SyntheticConfig read(const std::string& yaml) { return msf::ConfigFile::fromText(yaml, "c.yaml").get<SyntheticConfig>(); }

TEST(SyntheticConfig, DefaultsAreValidAndKittiLike) {
  const SyntheticConfig c;
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.frames, 10);
  EXPECT_DOUBLE_EQ(c.speed_mps / c.frame_rate_hz, 1.0); // 10 m/s at 10 Hz
  EXPECT_DOUBLE_EQ(c.lidar_max_range_m, 120.0);
  EXPECT_DOUBLE_EQ(c.lidar_upper_elevation_deg, 2.0);
  EXPECT_DOUBLE_EQ(c.lidar_lower_elevation_deg, -24.9);
  // Moving cars are on: one ahead, oncoming ones in pairs.
  EXPECT_EQ(c.moving_cars_ahead, 1);
  EXPECT_EQ(c.moving_cars_oncoming, 2);
}

TEST(SyntheticConfig, ReadOverridesOnlyThePresentKeys) {
  const SyntheticConfig c = read("%YAML:1.0\nsynthetic:\n  frames: 3\n  lidar_dropout: 0.1\n");
  EXPECT_EQ(c.frames, 3);
  EXPECT_DOUBLE_EQ(c.lidar_dropout, 0.1);
  EXPECT_EQ(c.seed, SyntheticConfig().seed);
  // An absent section changes nothing.
  EXPECT_EQ(read("other:\n  frames: 3\n").frames, 10);
}

TEST(SyntheticConfig, BadValuesNameTheirKey) {
  struct Case {
    const char* yaml;
    const char* key;
  };
  for (const Case& bad :
       {Case{"frames: 0", "synthetic.frames"}, Case{"supersampling: 9", "synthetic.supersampling"},
        Case{"lidar_dropout: 1.0", "synthetic.lidar_dropout"}, Case{"scene: moon", "synthetic.scene"},
        Case{"frames: many", "synthetic.frames"}, Case{"lidar_max_range_m: 0.5", "synthetic.lidar_max_range_m"},
        Case{"seed: -4", "synthetic.seed"}, Case{"moving_cars_ahead: -1", "synthetic.moving_cars_ahead"},
        Case{"moving_cars_oncoming: -2", "synthetic.moving_cars_oncoming"},
        Case{"moving_cars_oncoming: 2.5", "synthetic.moving_cars_oncoming"},
        Case{"oncoming_car_speed_mps: 0", "synthetic.oncoming_car_speed_mps"},
        Case{"oncoming_group_period_s: 0.5", "synthetic.oncoming_group_period_s"}}) {
    try {
      read(std::string("synthetic:\n  ") + bad.yaml + "\n");
      ADD_FAILURE() << bad.yaml << " was accepted";
    } catch (const msf::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(bad.key), std::string::npos) << e.what();
    }
  }
}

TEST(SyntheticConfig, PrintIsReadableYaml) {
  SyntheticConfig c;
  c.frames = 4;
  c.image_noise_sigma = 1.5;
  c.lidar_range_noise_m = 0.1 + 0.2; // not a short decimal: must still read back exactly
  c.speed_mps = 12;
  c.moving_cars_ahead = 0;
  c.moving_cars_oncoming = 3;
  c.oncoming_car_speed_mps = 8.5;
  c.oncoming_group_period_s = 6;
  c.lidar_model = "beams";
  c.lidar_beam_elevations_deg = {-15.0, 0.1 + 0.2, 7.5};
  c.camera = "pinhole";
  std::ostringstream out;
  msf::printConfig(out, c);
  const SyntheticConfig back = read(out.str());
  EXPECT_EQ(back.frames, 4);
  EXPECT_EQ(back.image_noise_sigma, 1.5);
  EXPECT_EQ(back.lidar_range_noise_m, 0.1 + 0.2);
  EXPECT_EQ(back.speed_mps, 12.0);
  EXPECT_EQ(back.moving_cars_ahead, 0);
  EXPECT_EQ(back.moving_cars_oncoming, 3);
  EXPECT_EQ(back.oncoming_car_speed_mps, 8.5);
  EXPECT_EQ(back.oncoming_group_period_s, 6.0);
  EXPECT_EQ(back.lidar_model, "beams");
  EXPECT_EQ(back.lidar_beam_elevations_deg, (std::vector<double>{-15.0, 0.1 + 0.2, 7.5}));
  EXPECT_EQ(back.camera, "pinhole");
  EXPECT_TRUE(back.principal_point_px.empty()); // printed as [], read back as none
}

TEST(SyntheticConfig, ProjectConfigFileHasAValidSection) {
  const std::string path = msf::test::sourceDir() + "/config/synthetic.yaml";
  ASSERT_TRUE(msf::test::fileExists(path)) << path;
  EXPECT_EQ(msf::ConfigFile(path).get<SyntheticConfig>().scene, "street");
}

} // namespace
