// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once

namespace msf {

/// Makes OpenCV allocate every image of 1 MiB or more on transparent huge pages: its own
/// mapping, aligned to 2 MiB and advised so. A freed image's mapping is kept (up to 64 MiB in all)
/// for the next image of its size, and returned to the system beyond that.
/// The pipeline allocates its per-frame images anew while frames are in flight, and the kernel
/// faults fresh memory in 4 KiB at a time: a 2 MiB page takes one fault where 512 took one each,
/// the larger share of that memory's cost on a virtual machine. Smaller images, and images on a
/// system without transparent huge pages, keep OpenCV's own allocator. Process-wide (it sets
/// cv::Mat's default allocator): for the tools' main(), not for a library that others link.
void useHugePagesForLargeImages();

} // namespace msf
