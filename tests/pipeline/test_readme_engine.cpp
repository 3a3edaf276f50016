// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The README's engine example, compiled from README.md itself (tests/CMakeLists.txt copies the
// block between <!-- example:engine:begin --> and <!-- example:engine:end --> into the build
// tree) and run on the test street: the README cannot drift from the API.
#include "readme_engine_example.h" // reconstructDrive(dataset, mesh_ply)

#include "pipeline_fixture.h"
#include "test_support.h"

#include <msf/io/cloud_io.h>

TEST_F(PipelineTest, TheReadmesEngineExampleMakesTheMeshOfADrive) {
  msf::test::TempDir dir;
  reconstructDrive(dataset(), dir.file("mesh.ply"));
  pcl::PolygonMesh mesh;
  msf::loadMesh(dir.file("mesh.ply"), mesh);
  EXPECT_GT(mesh.polygons.size(), 10000u);
}
