#include <msf/io/impl/cloud_io.hpp>

#include <pcl/io/obj_io.h>
#include <pcl/io/vtk_io.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace msf {

namespace {
/// LZF's largest ratio is a 264-byte match in 3 bytes; 100 bounds it.
constexpr std::uint64_t kMaxCompressionRatio = 100;

std::uint64_t plyTypeSize(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8")
    return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16")
    return 2;
  if (type == "double" || type == "float64")
    return 8;
  return 4; // int, uint, float and their sized names
}
} // namespace

namespace {

std::uintmax_t fileSize(const std::string& path) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec)
    throw IOError("'" + path + "' cannot be read: " + ec.message());
  return size;
}

[[noreturn]] void tooManyPoints(const std::string& path, const std::string& what, std::uint64_t count,
                                double needed, std::uintmax_t available) {
  char bytes[32];
  std::snprintf(bytes, sizeof bytes, "%.0f", needed);
  throw IOError("cloud '" + path + "' declares " + std::to_string(count) + " " + what + " in its header, " +
                "which need at least " + bytes + " bytes, but the file has " +
                std::to_string(available) + " after the header (a wrong or truncated file)");
}

/// PCL reads a value of an ASCII .pcd that is not a number ("abc") as 0 without a word:
/// every token of the body must be a number (nan and inf included).
void checkAsciiValues(const std::string& path, unsigned int data_index) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(data_index);
  std::string line, token;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ss(line);
    while (ss >> token) {
      char* end = nullptr;
      std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0')
        throw IOError("cloud '" + path + "': value '" + token + "' on data line " + std::to_string(line_no) +
                      " is not a number");
    }
  }
}

/// The smallest size the body of a .pcd with this header can have, checked against the
/// file before PCL allocates width x height x point_step bytes (POINTS 1e9 in a 1.4 KB file
/// asked for 6 GB and ended in std::bad_alloc).
void checkPcdBody(const std::string& path, const pcl::PCLPointCloud2& header, int data_type,
                  unsigned int data_index, bool check_values = true) {
  const std::uintmax_t size = fileSize(path);
  const std::uintmax_t available = size > data_index ? size - data_index : 0;
  const std::uint64_t points = static_cast<std::uint64_t>(header.width) * header.height;
  std::uint64_t values = 0, point_bytes = 0;
  for (const auto& f : header.fields) {
    const std::uint64_t count = std::max<std::uint32_t>(f.count, 1);
    values += count;
    point_bytes += count * std::max<std::size_t>(pcl::getFieldSize(f.datatype), 1);
  }
  // In double: width x height x point_step of a hostile header overflows 64 bits.
  const double n = static_cast<double>(points);
  const double needed = data_type == 0   ? n * static_cast<double>(values) * 2 - 1 // a value and a separator each
                        : data_type == 1 ? n * static_cast<double>(point_bytes)
                                         : n * static_cast<double>(point_bytes) / kMaxCompressionRatio;
  if (needed > static_cast<double>(available))
    tooManyPoints(path, "points", points, needed, available);
  if (data_type == 0 && check_values)
    checkAsciiValues(path, data_index);
}

/// PCL's readHeader itself sizes the cloud's data from WIDTH x HEIGHT (12 GB for POINTS
/// 1e9): the header is read here first, and its counts checked against the file's size.
/// A header this cannot read is left to PCL, which rejects it.
void checkPcdHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, word;
  std::vector<std::uint64_t> sizes, counts;
  double width = 1, height = 1, points = -1;
  int data_type = -1;
  std::size_t header_bytes = 0;
  while (header_bytes < (1u << 16) && std::getline(in, line)) {
    header_bytes += line.size() + 1;
    std::istringstream ss(line);
    if (!(ss >> word) || word[0] == '#')
      continue;
    auto numbers = [&](std::vector<std::uint64_t>& out) {
      double v = 0;
      while (ss >> v)
        out.push_back(v > 0 && v < 1e6 ? static_cast<std::uint64_t>(v) : 1);
    };
    if (word == "SIZE")
      numbers(sizes);
    else if (word == "COUNT")
      numbers(counts);
    else if (word == "WIDTH")
      ss >> width;
    else if (word == "HEIGHT")
      ss >> height;
    else if (word == "POINTS")
      ss >> points;
    else if (word == "DATA") {
      std::string kind;
      ss >> kind;
      data_type = kind == "ascii" ? 0 : kind == "binary" ? 1 : kind == "binary_compressed" ? 2 : -1;
      break;
    }
  }
  if (data_type < 0 || sizes.empty())
    return;
  pcl::PCLPointCloud2 header;
  const double n = std::max(width * height, points);
  if (!(n >= 0) || n > 1e18)
    throw IOError("cloud '" + path + "' declares " + std::to_string(n) + " points in its header");
  header.width = static_cast<std::uint32_t>(std::min(n, 4e9));
  header.height = 1;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    pcl::PCLPointField f;
    f.datatype = sizes[i] == 1 ? pcl::PCLPointField::UINT8 : sizes[i] == 2 ? pcl::PCLPointField::UINT16
               : sizes[i] == 8 ? pcl::PCLPointField::FLOAT64 : pcl::PCLPointField::FLOAT32;
    f.count = static_cast<std::uint32_t>(i < counts.size() ? counts[i] : 1);
    header.fields.push_back(f);
  }
  checkPcdBody(path, header, data_type, static_cast<unsigned int>(header_bytes), true);
}

/// The same for a .ply: its elements' counts (vertices, faces) against the file's size.
/// A header that cannot be read this way is left to PCL's reader.
void checkPlyBody(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line, format;
  struct Element {
    std::string name;
    std::uint64_t count = 0, bytes = 0, properties = 0;
  };
  std::vector<Element> elements;
  std::size_t header_bytes = 0;
  bool ended = false;
  while (header_bytes < (1u << 16) && std::getline(in, line)) {
    header_bytes += line.size() + 1;
    std::istringstream ss(line);
    std::string word;
    ss >> word;
    if (word == "format") {
      ss >> format;
    } else if (word == "element") {
      Element e;
      std::string count;
      ss >> e.name >> count;
      try {
        std::size_t used = 0;
        const double c = std::stod(count, &used);
        if (used != count.size() || !(c >= 0))
          return;
        e.count = c > 1e18 ? std::uint64_t(1e18) : static_cast<std::uint64_t>(c);
      } catch (const std::exception&) {
        return;
      }
      elements.push_back(e);
    } else if (word == "property" && !elements.empty()) {
      std::string type;
      ss >> type;
      if (type == "list")
        ss >> type; // the count's type: a list holds at least its count
      elements.back().bytes += plyTypeSize(type);
      ++elements.back().properties;
    } else if (word == "end_header") {
      ended = true;
      break;
    }
  }
  if (!ended)
    return;
  const std::uintmax_t size = fileSize(path);
  const std::uintmax_t available = size > header_bytes ? size - header_bytes : 0;
  const bool ascii = format == "ascii";
  for (const auto& e : elements) {
    const std::uint64_t per = ascii ? 2 * e.properties : e.bytes;
    if (per == 0)
      continue;
    const double needed = static_cast<double>(e.count) * static_cast<double>(per);
    if (needed > static_cast<double>(available) + 1)
      tooManyPoints(path, e.name + " elements", e.count, needed, available);
  }
}

} // namespace

void loadCloudBlob(const std::string& path, pcl::PCLPointCloud2& blob) {
  requireFile(path, "cloud");
  const std::string ext = fileExtension(path);
  int result = -1;
  // PCL's readers throw std::out_of_range and friends on some malformed headers (found by
  // fuzz/fuzz_cloud): those become an IOError naming the file, as the library promises.
  try {
    if (ext == ".pcd") {
      // PCL 1.13's PCDReader::read crashes on a file without a valid header: check it first.
      checkPcdHeader(path);
      pcl::PCDReader reader;
      Eigen::Vector4f origin;
      Eigen::Quaternionf orientation;
      int version = 0, data_type = 0;
      unsigned int data_index = 0;
      if (reader.readHeader(path, blob, origin, orientation, version, data_type, data_index) < 0 ||
          blob.fields.empty())
        throw IOError("cloud '" + path + "' is not a valid .pcd file (bad header)");
      if (static_cast<std::size_t>(blob.width) * blob.height == 0)
        throw IOError("cloud '" + path + "' has no points");
      checkPcdBody(path, blob, data_type, data_index, false); // the values were checked above
      result = reader.read(path, blob);
    } else if (ext == ".ply") {
      checkPlyBody(path);
      result = pcl::PLYReader().read(path, blob);
    } else {
      throw IOError("cloud '" + path + "' is neither .pcd nor .ply");
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw IOError("cloud '" + path + "' cannot be parsed as " + ext.substr(1) + ": " + e.what());
  }
  if (result < 0)
    throw IOError("cloud '" + path + "' cannot be parsed as " + ext.substr(1));
}

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh) {
  const std::string ext = fileExtension(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".vtk")
    throw IOError("cannot write mesh '" + path + "': use .ply, .obj or .vtk");
  writeAtomically(path, [&](const std::string& tmp) {
    int result = -1;
    if (ext == ".ply")
      result = pcl::io::savePLYFileBinary(tmp, mesh);
    else if (ext == ".obj")
      result = pcl::io::saveOBJFile(tmp, mesh);
    else
      result = pcl::io::saveVTKFile(tmp, mesh);
    if (result != 0)
      throw IOError("cannot write mesh '" + path + "'");
  });
}

void loadMesh(const std::string& path, pcl::PolygonMesh& mesh) {
  requireFile(path, "mesh");
  const std::string ext = fileExtension(path);
  int result = -1;
  if (ext == ".ply") {
    checkPlyBody(path);
    result = pcl::io::loadPLYFile(path, mesh);
  }
  else if (ext == ".obj")
    result = pcl::io::loadOBJFile(path, mesh);
  else if (ext == ".vtk")
    result = pcl::io::loadPolygonFileVTK(path, mesh);
  else
    throw IOError("mesh '" + path + "' is not .ply, .obj or .vtk");
  if (result < 0)
    throw IOError("mesh '" + path + "' cannot be parsed");
}

#define MSF_INSTANTIATE_CLOUD_IO(T)                                                \
  template void loadCloud<T>(const std::string&, pcl::PointCloud<T>&);            \
  template void saveCloud<T>(const std::string&, const pcl::PointCloud<T>&);
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZ)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZI)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZRGB)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZRGBA)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointNormal)

} // namespace msf
