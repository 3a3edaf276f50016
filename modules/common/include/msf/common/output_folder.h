// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <string>
#include <vector>

namespace msf {

/// A folder of outputs that never takes anything it did not write.
///
/// A run writes into a hidden staging folder beside the target (`.NAME.partial.PID.N`) and,
/// when it succeeds, commit() puts it in place of the target in one rename. The target may
/// be absent, empty, or an earlier output of the project: a folder whose manifest
/// (`.msf_manifest`, written by commit()) lists every file and folder in it. Anything else
/// in it (a user's file, a dataset, an output of an older version without a manifest) is
/// refused before the run, naming the entry, and the files of the earlier output are the
/// only ones ever removed. A failed or interrupted run leaves the target as it was; the
/// staging folder of a killed run is removed by the next run into the same target (it is
/// locked while its run lives).
class OutputFolder {
public:
  /// `tool` names the writer in the manifest and in messages ("msf_reconstruct").
  /// `inputs` are the paths the run reads (dataset folder, config, poses file): one inside
  /// the target is refused, since the target is replaced. Throws IOError naming the entry or
  /// the input at fault, or the parent folder when it is missing or not writable.
  OutputFolder(const std::string& path, const std::string& tool, const std::vector<std::string>& inputs = {});
  /// Removes the staging folder unless commit() succeeded.
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  /// The folder the run writes into (the staging folder).
  const std::string& dir() const { return staging_; }
  /// The folder as the user named it, made absolute.
  const std::string& target() const { return target_; }

  /// Writes the manifest of what the staging folder holds and puts it in place of the
  /// target. Checks the target again first (a file put there during the run is refused, and
  /// the target stays as it was). The earlier output's files are removed, and only they.
  void commit();

  /// The manifest's file name inside an output folder.
  static const char* manifestName();
  /// Throws IOError naming the first entry of `folder` that its manifest does not list
  /// (or the folder itself when it has entries and no manifest); nothing for an empty folder.
  static void requireOwnOutput(const std::string& folder, const std::string& tool);

private:
  void removeStaleStaging() const;
  void lockStaging();

  std::string target_, staging_, tool_;
  int lock_fd_ = -1;
  bool committed_ = false;
};

} // namespace msf
