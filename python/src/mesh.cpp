// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf::TriangleMesh as msfusion.Mesh: vertices (V, 3) float32, triangles (T, 3) int32, colours
// (V, 3) uint8 RGB and per-vertex weights (V,) float32, each a view of the mesh's own vectors;
// read from and written to .ply, .obj and .vtk as the msf_* tools do.
#include "bindings.h"

#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/reconstruction/marching_cubes.h>

#include <pcl/PolygonMesh.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>

#include <array>
#include <cstring>
#include <cstdint>
#include <limits>
#include <string>

namespace msf::python {

namespace {

static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "vertices are viewed as (V, 3) float32");
static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::uint32_t), "triangles as (T, 3)");
static_assert(sizeof(std::array<std::uint8_t, 3>) == 3, "colours as (V, 3) uint8");

/// A (rows, columns) view of `data`, or (rows,) for columns 0, kept alive by `owner`.
template <typename T>
py::array view(const void* data, std::size_t rows, int columns, const py::handle& owner) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  if (columns > 0)
    shape.push_back(columns);
  if (rows == 0)
    return py::array_t<T>(shape); // an empty vector's data() may be null
  return py::array_t<T>(shape, static_cast<const T*>(data), owner);
}

TriangleMesh& meshOf(const py::handle& self) { return self.cast<TriangleMesh&>(); }

/// Triangles (T, 3) of vertex indices below `vertices`.
void readTriangles(const py::handle& triangles, std::size_t vertices, TriangleMesh& mesh) {
  const cv::Mat t = rowsView(triangles, "triangles", CV_32S, 3, 3);
  mesh.triangles.resize(static_cast<std::size_t>(t.rows));
  for (int i = 0; i < t.rows; ++i)
    for (int k = 0; k < 3; ++k) {
      const int index = t.at<int>(i, k);
      if (index < 0 || static_cast<std::size_t>(index) >= vertices)
        throw InvalidInputError("triangles[" + std::to_string(i) + "] refers to vertex " + std::to_string(index) +
                                " of " + std::to_string(vertices));
      mesh.triangles[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(index);
    }
}

TriangleMesh fromArrays(const ArrayArg& vertices, const ArrayArg& triangles, const ArrayArg& colors) {
  const cv::Mat v = rowsView(vertices, "vertices", CV_32F, 3, 3);
  TriangleMesh mesh;
  mesh.vertices.reserve(static_cast<std::size_t>(v.rows));
  for (int i = 0; i < v.rows; ++i)
    mesh.vertices.emplace_back(v.at<float>(i, 0), v.at<float>(i, 1), v.at<float>(i, 2));
  readTriangles(triangles, mesh.vertices.size(), mesh);
  if (!colors.is_none()) {
    const cv::Mat c = rowsView(colors, "colors", CV_8U, 3, 3);
    if (static_cast<std::size_t>(c.rows) != mesh.vertices.size())
      throw InvalidInputError("colors has " + std::to_string(c.rows) + " rows for " +
                              std::to_string(mesh.vertices.size()) + " vertices");
    mesh.colors.resize(mesh.vertices.size());
    std::memcpy(mesh.colors.data(), c.data, mesh.colors.size() * 3);
  }
  return mesh;
}

/// Everything a Mesh holds, as copies of its arrays (a view without an owner copies), for pickle.
py::tuple meshState(const TriangleMesh& mesh) {
  const py::handle copied;
  const py::object colors = mesh.colors.empty()
                                ? py::object(py::none())
                                : view<std::uint8_t>(mesh.colors.data(), mesh.colors.size(), 3, copied);
  return py::make_tuple(view<float>(mesh.vertices.data(), mesh.vertices.size(), 3, copied),
                        view<std::int32_t>(mesh.triangles.data(), mesh.triangles.size(), 3, copied), colors,
                        view<float>(mesh.weights.data(), mesh.weights.size(), 0, copied));
}

/// The Mesh of meshState, checked as fromArrays checks arrays.
TriangleMesh meshFromState(const py::tuple& state) {
  if (state.size() != 4)
    throw InvalidInputError("a pickled Mesh holds 4 arrays, not " + std::to_string(state.size()));
  TriangleMesh mesh = fromArrays(py::object(state[0]), py::object(state[1]), py::object(state[2]));
  const auto weights = state[3].cast<py::array_t<float, py::array::c_style | py::array::forcecast>>();
  if (weights.size() != 0) {
    if (weights.ndim() != 1 || static_cast<std::size_t>(weights.size()) != mesh.vertices.size())
      throw InvalidInputError("a pickled Mesh's weights must be one per vertex");
    mesh.weights.assign(weights.data(), weights.data() + weights.size());
  }
  return mesh;
}

TriangleMesh readMesh(const std::filesystem::path& file) {
  const std::string path = file.string();
  pcl::PolygonMesh polygons;
  {
    py::gil_scoped_release release;
    loadMesh(path, polygons);
  }
  TriangleMesh mesh;
  const bool has_rgb = pcl::getFieldIndex(polygons.cloud, "rgb") >= 0 || pcl::getFieldIndex(polygons.cloud, "rgba") >= 0;
  if (has_rgb) {
    pcl::PointCloud<pcl::PointXYZRGB> points;
    pcl::fromPCLPointCloud2(polygons.cloud, points);
    for (const auto& p : points) {
      mesh.vertices.emplace_back(p.x, p.y, p.z);
      mesh.colors.push_back({p.r, p.g, p.b});
    }
  } else { // x y z only: PCL's conversion to a coloured point would warn of the missing field
    pcl::PointCloud<pcl::PointXYZ> points;
    pcl::fromPCLPointCloud2(polygons.cloud, points);
    for (const auto& p : points)
      mesh.vertices.emplace_back(p.x, p.y, p.z);
  }
  for (std::size_t i = 0; i < polygons.polygons.size(); ++i) {
    const auto& indices = polygons.polygons[i].vertices;
    if (indices.size() != 3)
      throw IOError("mesh '" + path + "': polygon " + std::to_string(i) + " has " + std::to_string(indices.size()) +
                    " vertices; msfusion.Mesh holds triangles");
    std::array<std::uint32_t, 3> triangle;
    for (std::size_t k = 0; k < 3; ++k) {
      if (indices[k] < 0 || static_cast<std::size_t>(indices[k]) >= mesh.vertices.size())
        throw IOError("mesh '" + path + "': polygon " + std::to_string(i) + " refers to vertex " +
                      std::to_string(indices[k]) + " of " + std::to_string(mesh.vertices.size()));
      triangle[k] = static_cast<std::uint32_t>(indices[k]);
    }
    mesh.triangles.push_back(triangle);
  }
  return mesh;
}

void saveTo(const TriangleMesh& mesh, const std::filesystem::path& path) {
  py::gil_scoped_release release;
  pcl::PolygonMesh polygons;
  mesh.toPolygonMesh(polygons);
  saveMesh(path.string(), polygons);
}

} // namespace

void bindMesh(py::module_& m) {
  py::class_<TriangleMesh> mesh_class(
      m, "Mesh",
      "A welded triangle mesh in metres, world frame: vertices (V, 3) float32, triangles (T, 3) int32 "
      "(counter-clockwise seen from outside), colors (V, 3) uint8 RGB and, from marching cubes, weights (V,) float32 "
      "(the lesser inverse variance of the two voxels that made each vertex; 0 where rays passed the one behind the "
      "surface since it last saw one: once, or component_release_passes frames in a row where a surface reappeared "
      "there after a pass). The arrays are views of the mesh: no copy.");
  copyable(mesh_class)
      .def(py::pickle(&meshState, &meshFromState))
      .def(py::init(&fromArrays), py::arg("vertices"), py::arg("triangles"), py::arg("colors") = py::none(),
           "A mesh from arrays (copied): vertices (V, 3) float32, triangles (T, 3) int32, colors (V, 3) uint8.")
      .def_property_readonly("vertices", [](const py::handle& self) {
        const TriangleMesh& mesh = meshOf(self);
        return view<float>(mesh.vertices.data(), mesh.vertices.size(), 3, self);
      })
      .def_property_readonly("triangles", [](const py::handle& self) {
        const TriangleMesh& mesh = meshOf(self);
        return view<std::int32_t>(mesh.triangles.data(), mesh.triangles.size(), 3, self);
      })
      .def_property_readonly("colors", [](const py::handle& self) {
        const TriangleMesh& mesh = meshOf(self);
        return view<std::uint8_t>(mesh.colors.data(), mesh.colors.size(), 3, self);
      })
      .def_property_readonly("weights", [](const py::handle& self) {
        const TriangleMesh& mesh = meshOf(self);
        return view<float>(mesh.weights.data(), mesh.weights.size(), 0, self);
      })
      .def("save", &saveTo, py::arg("path"),
           "Writes .ply (binary), .obj or .vtk, atomically (as msf_reconstruct writes mesh.ply).")
      .def("__repr__", [](const TriangleMesh& mesh) {
        return "Mesh(" + std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(mesh.triangles.size()) +
               " triangles)";
      });
  m.def("read_mesh", &readMesh, py::arg("path"),
        "A mesh from .ply, .obj or .vtk (msf_reconstruct's mesh.ply, msf_mesh's output). Raises IOError naming the "
        "file.");
}

} // namespace msf::python
