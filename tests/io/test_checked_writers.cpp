// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The writers of the io module on a full disk: an error naming the file and the reason, and no
// file left, where PCL's and OpenCV's writers returned success with a truncated file.
#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/poses.h>

#include "test_support.h"

#include <opencv2/core.hpp>
#include <pcl/io/obj_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/io/vtk_io.h>
#include <pcl/point_types.h>
#include <pcl/conversions.h>

#include <fstream>
#include <sstream>

namespace {

using msf::test::errorOf;

std::string contentOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A grid of n x n vertices in two triangles a cell, coloured.
pcl::PolygonMesh gridMesh(int n) {
  pcl::PointCloud<pcl::PointXYZRGB> vertices;
  for (int v = 0; v < n; ++v)
    for (int u = 0; u < n; ++u) {
      pcl::PointXYZRGB p;
      p.x = 0.01f * u, p.y = 0.01f * v, p.z = 0.001f * static_cast<float>((u * v) % 17);
      p.r = static_cast<std::uint8_t>(u), p.g = static_cast<std::uint8_t>(v), p.b = 7;
      vertices.push_back(p);
    }
  pcl::PolygonMesh mesh;
  pcl::toPCLPointCloud2(vertices, mesh.cloud);
  for (int v = 0; v + 1 < n; ++v)
    for (int u = 0; u + 1 < n; ++u) {
      const int a = v * n + u;
      pcl::Vertices t1, t2;
      t1.vertices = {a, a + 1, a + n};
      t2.vertices = {a + 1, a + n + 1, a + n};
      mesh.polygons.push_back(t1);
      mesh.polygons.push_back(t2);
    }
  return mesh;
}

TEST(CheckedWriters, AMeshIsWrittenByteForByteAsPclWritesIt) {
  msf::test::TempDir dir;
  const pcl::PolygonMesh mesh = gridMesh(120);
  for (const char* ext : {".ply", ".obj", ".vtk"})
    msf::saveMesh(dir.file(std::string("m") + ext), mesh);
  ASSERT_EQ(pcl::io::savePLYFileBinary(dir.file("pcl.ply"), mesh), 0);
  ASSERT_EQ(pcl::io::saveOBJFile(dir.file("pcl.obj"), mesh), 0);
  ASSERT_EQ(pcl::io::saveVTKFile(dir.file("pcl.vtk"), mesh), 0);
  // PCL's OBJ header names the file written, here the pipe the writer wrote through: all else equal.
  const auto withoutObjFileName = [](std::string text) { return text.erase(0, text.find("\nv ")); };
  EXPECT_TRUE(contentOf(dir.file("m.ply")) == contentOf(dir.file("pcl.ply")));
  EXPECT_TRUE(withoutObjFileName(contentOf(dir.file("m.obj"))) == withoutObjFileName(contentOf(dir.file("pcl.obj"))));
  EXPECT_TRUE(contentOf(dir.file("m.vtk")) == contentOf(dir.file("pcl.vtk")));
  EXPECT_NE(contentOf(dir.file("m.vtk")).find("POLYGONS " + std::to_string(mesh.polygons.size()) + " "),
            std::string::npos);
}

TEST(CheckedWriters, EveryWriterMeetsAFullDiskWithAnErrorAndLeavesNoFile) {
  MSF_FULL_FILESYSTEM(disk, 16384);
  const pcl::PolygonMesh mesh = gridMesh(120); // ~0.6 MB as any format
  for (const char* name : {"m.ply", "m.obj", "m.vtk"})
    EXPECT_EQ(errorOf([&] { msf::saveMesh(disk.file(name), mesh); }),
              "cannot write '" + disk.file(name) + "': No space left on device");
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  pcl::fromPCLPointCloud2(mesh.cloud, cloud);
  for (const char* name : {"c.pcd", "c.ply"})
    EXPECT_EQ(errorOf([&] { msf::saveCloud(disk.file(name), cloud); }),
              "cannot write '" + disk.file(name) + "': No space left on device");
  const msf::PoseList poses(2000, Eigen::Isometry3d::Identity());
  EXPECT_EQ(errorOf([&] { msf::saveOdometryPoses(disk.file("poses.txt"), poses); }),
            "cannot write '" + disk.file("poses.txt") + "': No space left on device");
  cv::Mat noise(400, 400, CV_8UC3);
  cv::randu(noise, 0, 255);
  EXPECT_EQ(errorOf([&] { msf::writeImage(disk.file("i.png"), noise); }),
            "cannot write '" + disk.file("i.png") + "': No space left on device");
  EXPECT_EQ(disk.countEntries(), 0u);
}

} // namespace
