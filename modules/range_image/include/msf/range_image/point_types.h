// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// PointXYZID lives with the other stages' point types in msf/io/point_types.h, so that every
// module (the integrator's toDepthFrame too) instantiates its templates for it.
#include <msf/io/point_types.h>
