// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The README's engine example as a program: a drive to a mesh, then its triangles counted.
#include "readme_engine_example.h" // reconstructDrive(dataset, mesh_ply)

#include <iostream>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: engine <dataset> <mesh.ply>\n";
    return 1;
  }
  reconstructDrive(argv[1], argv[2]);
  pcl::PolygonMesh mesh;
  msf::loadMesh(argv[2], mesh);
  std::cout << mesh.polygons.size() << " triangles\n";
}
