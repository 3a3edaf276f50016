// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// PCL's header draws its cube with y and z swapped against Bourke's page, but the tables only
// name corners and edges, and edges 0-11 join the same corners in both: (0,1) (1,2) (2,3)
// (3,0) (4,5) (5,6) (6,7) (7,4) (0,4) (1,5) (2,6) (3,7). marching_cubes.cpp places the
// corners at Bourke's positions (kCorner), as it did with its own copy of the tables.
#include "marching_cubes_tables.h"

#include <pcl/surface/marching_cubes.h>

namespace msf::detail {
const unsigned int (&kEdgeTable)[256] = pcl::edgeTable;
const int (&kTriTable)[256][16] = pcl::triTable;
} // namespace msf::detail
