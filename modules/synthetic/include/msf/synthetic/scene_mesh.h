// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/surface_classes.h>
#include <msf/synthetic/scene.h>

#include <pcl/PolygonMesh.h>

namespace msf::synthetic {

/// The scene's true surface as a triangle mesh in world coordinates (camera 0 at frame 0,
/// the world of poses/00.txt), with each material's base colour: flat faces split into
/// cells of at most `max_edge_m`, cylinders and ellipsoids tessellated finely enough to
/// stay within a few centimetres of the solid. Faces hidden inside another solid (a
/// building's foot on the sidewalk, the road under the sidewalk) are left out, so the mesh
/// is the visible boundary of the union, up to one cell at the seams. With `classes`, also
/// each vertex's SurfaceClass (by its material; names: surfaceClassName).
pcl::PolygonMesh sceneMesh(const Scene& scene, double max_edge_m, SurfaceClasses* classes = nullptr);

} // namespace msf::synthetic
