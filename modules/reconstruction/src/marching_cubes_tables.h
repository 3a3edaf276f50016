// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once

namespace msf::detail {
/// Paul Bourke's marching cubes tables as PCL ships them (pcl/surface/marching_cubes.h), read
/// through these references so that only marching_cubes_tables.cpp compiles PCL's surface
/// header. kEdgeTable[case]: bit e set when edge e crosses the surface; kTriTable[case]: the
/// triangles as edge triples, ended by -1. Corner i is "inside" (bit i of the case) when its
/// sdf is < 0; corners and edges are numbered as marching_cubes.cpp's kCorner and kEdge.
extern const unsigned int (&kEdgeTable)[256];
extern const int (&kTriTable)[256][16];
} // namespace msf::detail
