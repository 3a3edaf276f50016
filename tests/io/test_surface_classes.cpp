// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/surface_classes.h>

#include "test_support.h"

#include <fstream>

namespace {

std::string writeFile(const msf::test::TempDir& dir, const std::string& text) {
  const std::string path = dir.path() + "/scene_classes.txt";
  std::ofstream(path) << text;
  return path;
}

void expectIOError(const std::string& path, std::size_t vertices, const std::string& words) {
  try {
    msf::readSurfaceClasses(path, vertices);
    FAIL() << "no error for " << words;
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(SurfaceClasses, RunsReadBackToTheSameClasses) {
  msf::SurfaceClasses classes;
  classes.names = {"ground", "building", "tree"};
  classes.vertex_class = {0, 0, 0, 2, 2, 1, 0, 0};
  const std::string text = msf::formatSurfaceClasses(classes);
  EXPECT_NE(text.find("0 3 ground\n3 2 tree\n5 1 building\n6 2 ground\n"), std::string::npos) << text;
  msf::test::TempDir dir;
  const msf::SurfaceClasses back = msf::readSurfaceClasses(writeFile(dir, text), 8);
  // Names in order of first appearance; every vertex keeps its name.
  ASSERT_EQ(back.vertex_class.size(), 8u);
  for (std::size_t i = 0; i < 8; ++i)
    EXPECT_EQ(back.names[back.vertex_class[i]], classes.names[classes.vertex_class[i]]) << i;
}

TEST(SurfaceClasses, AClassWithoutANameIsRefused) {
  msf::SurfaceClasses classes;
  classes.names = {"ground"};
  classes.vertex_class = {0, 1};
  EXPECT_THROW(msf::formatSurfaceClasses(classes), msf::InvalidInputError);
}

TEST(SurfaceClasses, BadFilesNameTheFileAndWhatIsWrong) {
  msf::test::TempDir dir;
  expectIOError(dir.path() + "/none.txt", 0, "cannot open");
  expectIOError(writeFile(dir, "0 3 ground\n3 x tree\n"), 0, "line 2: expected 'first_vertex vertex_count class'");
  expectIOError(writeFile(dir, "0 3 ground extra\n"), 0, "line 1: expected");
  expectIOError(writeFile(dir, "0 0 ground\n"), 0, "line 1: expected");
  expectIOError(writeFile(dir, "0 3 ground\n4 2 tree\n"), 0, "line 2: the run begins at vertex 4, the last ended at 3");
  expectIOError(writeFile(dir, "0 3 ground\n3 2 tree\n"), 6, "cover 5 vertices, the mesh has 6");
  expectIOError(writeFile(dir, "0 3 ground\n3 4 tree\n"), 6, "line 2: the run of 4 vertices from 3 goes past the mesh's 6");
  // A count that would take all memory (or wrap) is refused before anything is allocated.
  expectIOError(writeFile(dir, "0 18446744073709551615 ground\n"), 0, "goes past 2^32 vertices");
  expectIOError(writeFile(dir, "0 1 ground\n1 18446744073709551615 tree\n"), 5, "goes past the mesh's 5");
  expectIOError(writeFile(dir, "0 99999999999999999999999 ground\n"), 0, "line 1: expected");
}

} // namespace
