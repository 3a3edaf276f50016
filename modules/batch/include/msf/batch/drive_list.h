// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/frame_source.h>

#include <memory>
#include <string>
#include <vector>

namespace msf {

/// One drive of a batch: a dataset msf_reconstruct reads, and where its poses come from.
struct Drive {
  std::string name;     ///< unique in a batch: its output is OUT/drives/NAME
  std::string dataset;  ///< the sequence folder or bag file, absolute
  /// A poses file (KITTI's format, line i for frame i) in the batch's shared world, or "" for
  /// the dataset's own poses (a synthetic street's, odometry ground truth, raw OXTS).
  std::string poses;
};

/// The drives under `path`: `path` itself when it is one (a KITTI odometry sequence, a KITTI raw
/// drive, a synthetic root with one sequence, a folder of the generic layout, a ROS bag), else
/// the drives one or two levels down (ROOT/sequences/NN, ROOT/DATE/DATE_drive_NNNN_sync,
/// ROOT/STREET/sequences/00, ROOT/NAME/ of the generic layout, ROOT/NAME.bag), sorted by path.
/// Throws IOError naming `path` when it holds none.
std::vector<Drive> findDrives(const std::string& path);

/// A list of drives, one a line: "DATASET [POSES]" (paths relative to the list's folder,
/// separated by a tab or spaces; a path with a space needs the tab), blank lines and lines
/// starting with '#' skipped; each DATASET must be one drive. Throws IOError naming the
/// file and line of a line that is not.
std::vector<Drive> readDriveList(const std::string& path);

/// Names the drives by their folders (a synthetic street's root, an odometry sequence's number,
/// a raw drive's or a generic layout's folder) or a bag's file name without its extension.
/// Throws InvalidInputError naming two drives of one name, or one dataset given twice.
void nameDrives(std::vector<Drive>& drives);

/// The drive's dataset, opened as msf_reconstruct opens it without options (openDataset). Throws
/// InvalidInputError naming the drive when it cannot, and saying how to make it one msf_batch
/// reads (msf_convert with -rig or a bag's topic options).
std::unique_ptr<FrameSource> openDrive(const Drive& drive);

} // namespace msf
