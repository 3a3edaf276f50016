// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/parallel.h>
#include <msf/io/compressed_pcd.h>

#include <pcl/io/lzf.h>
#include <pcl/io/pcd_io.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <locale>
#include <memory>
#include <sstream>
#include <vector>

namespace msf {

namespace {

/// A field as the compressed body holds it: a plane of `bytes` per point, read at `offset`.
struct FieldPlane {
  std::size_t offset, bytes;
};

std::vector<FieldPlane> fieldPlanes(const pcl::PCLPointCloud2& blob) {
  std::vector<FieldPlane> planes;
  for (const auto& field : blob.fields)
    if (field.name != "_") // padding
      planes.push_back({field.offset, static_cast<std::size_t>(field.count) * pcl::getFieldSize(field.datatype)});
  return planes;
}

/// The points' fields, each field's values side by side (x x x ... y y y ...), which compresses
/// better than whole points.
std::unique_ptr<char[]> fieldsSideBySide(const std::uint8_t* data, std::size_t step,
                                         const std::vector<FieldPlane>& fields, std::size_t points, std::size_t bytes) {
  std::unique_ptr<char[]> planes(new char[bytes]);
  std::vector<char*> starts;
  std::size_t start = 0;
  for (const FieldPlane& f : fields) {
    starts.push_back(planes.get() + start);
    start += f.bytes * points;
  }
  parallelFor(cv::Range(0, static_cast<int>(points)), [&](const cv::Range& range) {
    for (std::size_t j = 0; j < fields.size(); ++j) {
      const FieldPlane& f = fields[j];
      for (int i = range.start; i < range.end; ++i)
        std::memcpy(starts[j] + static_cast<std::size_t>(i) * f.bytes, data + i * step + f.offset, f.bytes);
    }
  });
  return planes;
}

/// PCL's header, with `comment` after its first line.
std::string header(const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin,
                   const Eigen::Quaternionf& orientation, const std::string& comment) {
  std::ostringstream text;
  text.imbue(std::locale::classic());
  if (pcl::PCDWriter().generateHeaderBinaryCompressed(text, blob, origin, orientation) != 0)
    throw IOError("PCL cannot write the header of a cloud of " + std::to_string(blob.fields.size()) + " fields");
  std::string out = text.str();
  out.insert(out.find('\n') + 1, comment);
  return out + "DATA binary_compressed\n";
}

} // namespace

void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin,
                        const Eigen::Quaternionf& orientation, const std::string& comment) {
  writeCompressedPcd(out, blob, blob.data.data(), blob.data.size(), origin, orientation, comment);
}

void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& layout, const std::uint8_t* data,
                        std::size_t data_bytes, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                        const std::string& comment) {
  const std::vector<FieldPlane> fields = fieldPlanes(layout);
  const std::size_t points = static_cast<std::size_t>(layout.width) * layout.height;
  std::size_t point_bytes = 0;
  for (const FieldPlane& f : fields)
    point_bytes += f.bytes;
  // The format keeps its sizes in 32 bits, and the compressed body may need half as much again.
  const std::size_t bytes = points * point_bytes, room = bytes * 3 / 2;
  constexpr std::size_t kMaxBytes = std::numeric_limits<std::uint32_t>::max() / 3 * 2;
  if (bytes > kMaxBytes)
    throw IOError("its " + std::to_string(points) + " points of " + std::to_string(point_bytes) + " bytes make " +
                  std::to_string(bytes) + " bytes, more than a binary_compressed .pcd holds (" +
                  std::to_string(kMaxBytes) + ": its sizes are 32-bit)");
  if (data_bytes < points * layout.point_step)
    throw IOError("its data holds " + std::to_string(data_bytes) + " bytes, not its " +
                  std::to_string(points) + " points of " + std::to_string(layout.point_step));
  std::uint32_t sizes[2] = {0, 0}; // compressed, uncompressed
  std::unique_ptr<char[]> compressed;
  if (bytes > 0) {
    const std::unique_ptr<char[]> planes = fieldsSideBySide(data, layout.point_step, fields, points, bytes);
    compressed.reset(new char[room]);
    sizes[0] = pcl::lzfCompress(planes.get(), static_cast<unsigned int>(bytes), compressed.get(),
                                static_cast<unsigned int>(room));
    sizes[1] = static_cast<std::uint32_t>(bytes);
    if (sizes[0] == 0)
      throw IOError("its " + std::to_string(bytes) + " bytes do not compress");
  }
  const std::string text = header(layout, origin, orientation, comment);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.write(reinterpret_cast<const char*>(sizes), sizeof(sizes));
  out.write(compressed.get(), static_cast<std::streamsize>(sizes[0]));
}

} // namespace msf
