// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/batch/batch_plan.h>

#include <cstddef>
#include <string>

namespace msf {

/// Every drive's frames integrated into one volume by one process, drive after drive in the
/// plan's order, streamed as a drive's run is: the map that merging the drives' stores equals
/// where integration is a plain weighted mean (docs/batch.md), for checks on a few small
/// drives. Written to `out` (an OutputFolder): tsdf/, tiles/, mesh.ply and summary.json (frames,
/// seconds, triangles). Returns the triangles. Throws InvalidInputError when the drives'
/// calibrations differ (one pipeline runs them all) or a drive has no known poses, and what
/// Reconstructor throws.
std::size_t reconstructInOneProcess(const BatchPlan& plan, const std::string& out);

} // namespace msf
