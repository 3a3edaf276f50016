// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/parallel.h>
#include <msf/io/compressed_pcd.h>

#include <pcl/io/lzf.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <locale>
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

/// The points' fields laid out as the body holds them, each field's values side by side
/// (x x x ... y y y ...), which compresses better than whole points.
struct FieldsSideBySide {
  const std::uint8_t* data;
  std::size_t step, points;
  std::vector<FieldPlane> fields;

  std::size_t bytes() const {
    std::size_t total = 0;
    for (const FieldPlane& f : fields)
      total += f.bytes * points;
    return total;
  }

  /// Bytes [begin, end) of the layout into `out`; a piece may start or end within a value.
  void copy(std::size_t begin, std::size_t end, char* out) const {
    std::size_t plane = 0; // where the field's plane starts
    for (const FieldPlane& f : fields) {
      const std::size_t plane_end = plane + f.bytes * points;
      std::size_t b = std::max(begin, plane);
      const std::size_t to = std::min(end, plane_end);
      if (b < to) {
        char* o = out + (b - begin);
        const std::uint8_t* value = data + (b - plane) / f.bytes * step + f.offset;
        if (const std::size_t within = (b - plane) % f.bytes) { // the end of a value the last piece began
          const std::size_t n = std::min(f.bytes - within, to - b);
          std::memcpy(o, value + within, n);
          o += n, b += n, value += step;
        }
        for (; b + f.bytes <= to; o += f.bytes, b += f.bytes, value += step)
          std::memcpy(o, value, f.bytes);
        if (b < to)
          std::memcpy(o, value, to - b);
      }
      plane = plane_end;
    }
  }
};

/// LZF's stream of the layout (pcl::lzfCompress), compressed in pieces of kPieceBytes on every
/// core. LZF refers back only within what its stream wrote, so the pieces' streams one after
/// another are one stream that any LZF reader (PCL's) decompresses whole; a body of one piece
/// is PCL's own. Pieces of a fixed size: the same bytes on any number of threads.
std::vector<std::vector<char>> compressInPieces(const FieldsSideBySide& layout) {
  constexpr std::size_t kPieceBytes = std::size_t{1} << 20; // LZF's window is 8 KiB: the ratio barely changes
  const std::size_t bytes = layout.bytes(), pieces = (bytes + kPieceBytes - 1) / kPieceBytes;
  std::vector<std::vector<char>> compressed(pieces);
  parallelFor(cv::Range(0, static_cast<int>(pieces)), [&](const cv::Range& range) {
    std::vector<char> piece(kPieceBytes);
    for (int k = range.start; k < range.end; ++k) {
      const std::size_t start = static_cast<std::size_t>(k) * kPieceBytes;
      const std::size_t length = std::min(kPieceBytes, bytes - start);
      layout.copy(start, start + length, piece.data());
      std::vector<char>& out = compressed[static_cast<std::size_t>(k)];
      out.resize(length * 3 / 2 + 16);
      const unsigned int written = pcl::lzfCompress(piece.data(), static_cast<unsigned int>(length), out.data(),
                                                    static_cast<unsigned int>(out.size()));
      out.resize(written); // 0: it did not compress
    }
  });
  for (const std::vector<char>& piece : compressed)
    if (piece.empty())
      throw IOError("its " + std::to_string(bytes) + " bytes do not compress");
  return compressed;
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
  const std::size_t bytes = points * point_bytes;
  constexpr std::size_t kMaxBytes = std::numeric_limits<std::uint32_t>::max() / 3 * 2;
  if (bytes > kMaxBytes)
    throw IOError("its " + std::to_string(points) + " points of " + std::to_string(point_bytes) + " bytes make " +
                  std::to_string(bytes) + " bytes, more than a binary_compressed .pcd holds (" +
                  std::to_string(kMaxBytes) + ": its sizes are 32-bit)");
  if (data_bytes < points * layout.point_step)
    throw IOError("its data holds " + std::to_string(data_bytes) + " bytes, not its " +
                  std::to_string(points) + " points of " + std::to_string(layout.point_step));
  const FieldsSideBySide body{data, layout.point_step, points, fields};
  const std::vector<std::vector<char>> pieces = compressInPieces(body);
  std::size_t compressed = 0;
  for (const std::vector<char>& piece : pieces)
    compressed += piece.size();
  if (compressed > std::numeric_limits<std::uint32_t>::max())
    throw IOError("its " + std::to_string(bytes) + " bytes compress to more than the format's 32-bit sizes hold");
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(compressed), static_cast<std::uint32_t>(bytes)};
  const std::string text = header(layout, origin, orientation, comment);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.write(reinterpret_cast<const char*>(sizes), sizeof(sizes));
  for (const std::vector<char>& piece : pieces)
    out.write(piece.data(), static_cast<std::streamsize>(piece.size()));
}

} // namespace msf
