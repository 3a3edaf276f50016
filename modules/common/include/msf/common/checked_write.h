// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <functional>
#include <ostream>
#include <string>

/// Writes checked to their end. std::ofstream, FILE* and the writers of PCL and OpenCV built
/// on them report nothing of a write the system refuses at their last flush or close (a full
/// disk, a quota, an I/O error): the file is then silently truncated. Every byte written here
/// goes through write(2) and close(2) with their result checked; a failure throws IOError
/// naming the file and the system's reason (its errno, not that of the cleanup), and, as the
/// writes are atomic (writeAtomically), leaves no file.
namespace msf {

/// Writes `path` atomically through `out`, which `write` fills (text or binary alike).
void writeStreamAtomically(const std::string& path, const std::function<void(std::ostream& out)>& write);

/// Writes `size` bytes at `data` to `path` atomically (an encoded image, a buffer).
void writeBytesAtomically(const std::string& path, const void* data, std::size_t size);

/// Writes `path` atomically by a library writer that takes a file name and does not check its
/// writes (PCL's .ply, .obj, .vtk and ASCII .pcd writers): `write` gets the name of a pipe
/// (/proc/self/fd/N) and writes the file into it; a thread copies the bytes into the file,
/// each write checked. `write` must write front to back, without seeking; it may open the
/// name more than once (PCL's binary .ply writer appends its body to its header).
void writeThroughPipeAtomically(const std::string& path, const std::function<void(const std::string& sink)>& write);

} // namespace msf
