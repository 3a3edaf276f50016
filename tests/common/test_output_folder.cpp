// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// OutputFolder: a run's outputs replace only what an earlier run wrote, never a user's file.
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>

#include <test_support.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;
using msf::OutputFolder;
using msf::test::errorOf;
using msf::test::TempDir;

namespace {

void writeText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A run of `tool` into `target` that writes `files` (relative paths) and commits.
void runInto(const std::string& target, const std::vector<std::string>& files, const std::string& text = "new") {
  OutputFolder out(target, "msf_test");
  for (const std::string& f : files)
    writeText(fs::path(out.dir()) / f, text);
  out.commit();
}

} // namespace

TEST(OutputFolder, ANewFolderHoldsTheRunsFilesAndAManifestListingThem) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"mesh.ply", "tiles/0_0_0.ply"});
  EXPECT_EQ(readText(fs::path(target) / "mesh.ply"), "new");
  const std::string manifest = readText(fs::path(target) / OutputFolder::manifestName());
  EXPECT_NE(manifest.find("\nmesh.ply\n"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\ntiles/\n"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\ntiles/0_0_0.ply\n"), std::string::npos) << manifest;
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u); // no staging folder left beside it
}

TEST(OutputFolder, AnEarlierOutputIsReplacedWholeAndOnlyItsOwnFilesGo) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"mesh.ply", "depth/000000.pcd", "old_only.png"}, "old");
  runInto(target, {"mesh.ply"});
  EXPECT_EQ(readText(fs::path(target) / "mesh.ply"), "new");
  EXPECT_FALSE(fs::exists(fs::path(target) / "old_only.png"));
  EXPECT_FALSE(fs::exists(fs::path(target) / "depth"));
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

TEST(OutputFolder, AnEmptyFolderIsTaken) {
  TempDir dir;
  const std::string target = dir.file("out");
  fs::create_directory(target);
  runInto(target, {"mesh.ply"});
  EXPECT_TRUE(fs::exists(fs::path(target) / "mesh.ply"));
}

TEST(OutputFolder, AFolderOfTheUsersIsRefusedNamingTheFileAndLeftAsItWas) {
  TempDir dir;
  const std::string target = dir.file("photos");
  writeText(fs::path(target) / "notes.txt", "mine");
  writeText(fs::path(target) / "holiday.png", "mine");
  const std::string error = errorOf([&] { OutputFolder(target, "msf_test"); });
  EXPECT_NE(error.find("photos"), std::string::npos) << error;
  EXPECT_NE(error.find("holiday.png"), std::string::npos) << error; // the first entry, in name order
  EXPECT_EQ(readText(fs::path(target) / "notes.txt"), "mine");
  EXPECT_EQ(msf::test::countEntries(target), 2u);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

TEST(OutputFolder, AFileTheUserAddedToAnEarlierOutputIsRefusedAndKept) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"mesh.ply", "tiles/0_0_0.ply"}, "old");
  writeText(fs::path(target) / "tiles" / "my_edit.ply", "mine");
  const std::string error = errorOf([&] { runInto(target, {"mesh.ply"}); });
  EXPECT_NE(error.find("tiles/my_edit.ply"), std::string::npos) << error;
  EXPECT_EQ(readText(fs::path(target) / "mesh.ply"), "old");
  EXPECT_EQ(readText(fs::path(target) / "tiles" / "my_edit.ply"), "mine");
}

TEST(OutputFolder, AFilePutThereDuringTheRunStopsTheCommitAndTheEarlierOutputStays) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"mesh.ply"}, "old");
  {
    OutputFolder out(target, "msf_test");
    writeText(fs::path(out.dir()) / "mesh.ply", "new");
    writeText(fs::path(target) / "notes.txt", "mine"); // the user, meanwhile
    const std::string error = errorOf([&] { out.commit(); });
    EXPECT_NE(error.find("notes.txt"), std::string::npos) << error;
  }
  EXPECT_EQ(readText(fs::path(target) / "mesh.ply"), "old");
  EXPECT_EQ(readText(fs::path(target) / "notes.txt"), "mine");
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u); // the staging folder went
}

TEST(OutputFolder, ARunThatDoesNotCommitLeavesTheTargetAsItWas) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"mesh.ply"}, "old");
  {
    OutputFolder out(target, "msf_test");
    writeText(fs::path(out.dir()) / "mesh.ply", "half");
  }
  EXPECT_EQ(readText(fs::path(target) / "mesh.ply"), "old");
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

TEST(OutputFolder, AnInputInsideTheTargetIsRefused) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"config.yaml", "poses.txt"});
  const std::string error =
      errorOf([&] { OutputFolder(target, "msf_test", {"", target + "/./config.yaml"}); });
  EXPECT_NE(error.find("config.yaml"), std::string::npos) << error;
  EXPECT_NE(error.find("inside the output folder"), std::string::npos) << error;
  EXPECT_NE(errorOf([&] { OutputFolder(target, "msf_test", {target}); }), "(no error)");
  EXPECT_EQ(errorOf([&] { OutputFolder(dir.file("elsewhere"), "msf_test", {target + "/poses.txt"}); }), "(no error)");
}

TEST(OutputFolder, APlainFileOrASymbolicLinkIsNotAnOutputFolder) {
  TempDir dir;
  writeText(dir.file("file"), "x");
  EXPECT_NE(errorOf([&] { OutputFolder(dir.file("file"), "msf_test"); }).find("not a folder"), std::string::npos);
  fs::create_directory(dir.file("real"));
  fs::create_directory_symlink(dir.file("real"), dir.file("link"));
  const std::string link = errorOf([&] { OutputFolder(dir.file("link"), "msf_test"); });
  EXPECT_NE(link.find("output folder '" + dir.file("link") + "' is a symbolic link (to '" + dir.file("real") +
                      "'), which the run's folder would replace: give the folder it points to"),
            std::string::npos)
      << link;
  EXPECT_TRUE(fs::is_symlink(dir.file("link")));
  EXPECT_NE(errorOf([&] { OutputFolder(dir.file("missing/out"), "msf_test"); }).find("does not exist"),
            std::string::npos);
}

TEST(OutputFolder, ALinkInsideAnEarlierOutputIsNotItsOwn) {
  TempDir dir;
  const std::string target = dir.file("out");
  runInto(target, {"mesh.ply"});
  fs::create_directory(dir.file("data"));
  writeText(dir.file("data/keep.bin"), "mine");
  fs::create_directory_symlink(dir.file("data"), fs::path(target) / "data");
  const std::string error = errorOf([&] { runInto(target, {"mesh.ply"}); });
  EXPECT_NE(error.find("'data'"), std::string::npos) << error;
  EXPECT_EQ(readText(dir.file("data/keep.bin")), "mine");
}

TEST(OutputFolder, AKilledRunsStagingIsRemovedByTheNextAndALiveOnesIsNot) {
  TempDir dir;
  const std::string target = dir.file("out");
  // A killed run's staging folder: its lock file is there, and no process holds it.
  const fs::path stale = fs::path(dir.path()) / ".out.partial.1";
  writeText(stale / ".msf_staging", "");
  writeText(stale / "mesh.ply", "half");
  // A folder of that name without the lock file is not ours: it stays.
  const fs::path other = fs::path(dir.path()) / ".out.partial.2";
  writeText(other / "keep.txt", "mine");
  OutputFolder live(target, "msf_test");
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(other / "keep.txt"));
  {
    OutputFolder second(target, "msf_test"); // a second output of the same process to the same target
  }
  EXPECT_TRUE(fs::exists(live.dir())) << "a live run's staging folder was removed";
}
