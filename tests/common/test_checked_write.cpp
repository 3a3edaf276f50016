// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>

#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

std::string contentOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Bytes that do not compress or repeat: what a writer puts on a disk.
std::string bytes(std::size_t n) {
  std::string s(n, '\0');
  for (std::size_t i = 0; i < n; ++i)
    s[i] = static_cast<char>((i * 2654435761u) >> 13);
  return s;
}

TEST(CheckedWrite, AStreamIsWrittenWholeThroughATemporary) {
  msf::test::TempDir dir;
  const std::string text = bytes(300000); // more than the stream's buffer
  msf::writeStreamAtomically(dir.file("a.bin"), [&](std::ostream& out) {
    out.write(text.data(), 1000);
    out << text.substr(1000);
  });
  EXPECT_EQ(contentOf(dir.file("a.bin")), text);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

TEST(CheckedWrite, AFileNamedWriterWritesThroughThePipeAndMayOpenItTwice) {
  // As PCL's binary .ply writer: the header through one stream, the body appended through another.
  msf::test::TempDir dir;
  const std::string body = bytes(500000);
  msf::writeThroughPipeAtomically(dir.file("m.ply"), [&](const std::string& sink) {
    std::ofstream(sink) << "header\n";
    std::ofstream(sink, std::ios::app | std::ios::binary).write(body.data(), static_cast<std::streamsize>(body.size()));
  });
  EXPECT_EQ(contentOf(dir.file("m.ply")), "header\n" + body);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

TEST(CheckedWrite, AWriterThatThrowsLeavesNothing) {
  msf::test::TempDir dir;
  EXPECT_THROW(msf::writeThroughPipeAtomically(dir.file("m.ply"),
                                               [&](const std::string& sink) {
                                                 std::ofstream(sink) << "half";
                                                 throw msf::IOError("the writer failed");
                                               }),
               msf::IOError);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 0u);
}

TEST(CheckedWrite, AFullDiskIsAnErrorWithItsReasonAndLeavesNoFile) {
  // 8 KB free: each writer gets its first bytes onto the disk, then meets the full disk. A plain
  // std::ofstream (or PCL's writers) reports nothing of it at its last flush: the file is cut.
  MSF_FULL_FILESYSTEM(disk, 8192);
  const std::string data = bytes(200000);
  const std::string stream = msf::test::errorOf([&] {
    msf::writeStreamAtomically(disk.file("poses.txt"), [&](std::ostream& out) { out << data; });
  });
  EXPECT_EQ(stream, "cannot write '" + disk.file("poses.txt") + "': No space left on device");
  const std::string pipe = msf::test::errorOf([&] {
    msf::writeThroughPipeAtomically(disk.file("mesh.ply"), [&](const std::string& sink) { std::ofstream(sink) << data; });
  });
  EXPECT_EQ(pipe, "cannot write '" + disk.file("mesh.ply") + "': No space left on device");
  const std::string block = msf::test::errorOf([&] { msf::writeBytesAtomically(disk.file("a.png"), data.data(), data.size()); });
  EXPECT_EQ(block, "cannot write '" + disk.file("a.png") + "': No space left on device");
  EXPECT_EQ(disk.countEntries(), 0u);
  // What fits is written.
  msf::writeStreamAtomically(disk.file("small.txt"), [&](std::ostream& out) { out << "fits"; });
  EXPECT_EQ(contentOf(disk.file("small.txt")), "fits");
}

TEST(CheckedWrite, ARenameThatFailsNamesItsOwnReason) {
  // The cleanup's success used to overwrite the failure: "rename failed: Success".
  msf::test::TempDir dir;
  std::filesystem::create_directories(dir.file("out.txt/inside"));
  const std::string e = msf::test::errorOf(
      [&] { msf::writeStreamAtomically(dir.file("out.txt"), [](std::ostream& out) { out << "x"; }); });
  EXPECT_NE(e.find("rename failed: Is a directory"), std::string::npos) << e;
  EXPECT_EQ(e.find("Success"), std::string::npos) << e;
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

} // namespace
