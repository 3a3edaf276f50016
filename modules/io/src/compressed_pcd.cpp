// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/parallel.h>
#include <msf/io/compressed_pcd.h>

#include <pcl/io/lzf.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <type_traits>
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

/// `n` values of `bytes` each from `in`, every `in_step` bytes, to `out`, every `out_step`
/// bytes; the common sizes copied as such, not by a call per value.
void copyValues(const std::uint8_t* in, std::size_t in_step, std::uint8_t* out, std::size_t out_step,
                std::size_t bytes, std::size_t n) {
  auto copy = [&](auto value_bytes) {
    constexpr std::size_t size = decltype(value_bytes)::value;
    for (std::size_t i = 0; i < n; ++i, in += in_step, out += out_step)
      std::memcpy(out, in, size);
  };
  switch (bytes) {
  case 1: return copy(std::integral_constant<std::size_t, 1>());
  case 2: return copy(std::integral_constant<std::size_t, 2>());
  case 4: return copy(std::integral_constant<std::size_t, 4>());
  case 8: return copy(std::integral_constant<std::size_t, 8>());
  default:
    for (std::size_t i = 0; i < n; ++i, in += in_step, out += out_step)
      std::memcpy(out, in, bytes);
  }
}

/// The points' fields laid out as the body holds them, each field's values side by side
/// (x x x ... y y y ...), which compresses better than whole points.
struct FieldsSideBySide {
  const FieldValues& values;
  std::size_t points;
  std::vector<FieldPlane> fields;

  std::size_t bytes() const {
    std::size_t total = 0;
    for (const FieldPlane& f : fields)
      total += f.bytes * points;
    return total;
  }

  /// Bytes [begin, end) of the layout into `out`; a piece may start or end within a value.
  void copy(std::size_t begin, std::size_t end, char* out) const {
    std::vector<char> value; // a value cut by the piece's start or end
    std::size_t plane = 0;   // where the field's plane starts
    for (std::size_t j = 0; j < fields.size(); ++j) {
      const std::size_t bytes = fields[j].bytes, plane_end = plane + bytes * points;
      std::size_t b = std::max(begin, plane);
      const std::size_t to = std::min(end, plane_end);
      if (b < to) {
        char* o = out + (b - begin);
        std::size_t point = (b - plane) / bytes;
        value.resize(bytes);
        if (const std::size_t within = (b - plane) % bytes) { // the end of a value the last piece began
          values(j, point++, 1, value.data());
          const std::size_t n = std::min(bytes - within, to - b);
          std::memcpy(o, value.data() + within, n);
          o += n, b += n;
        }
        const std::size_t whole = (to - b) / bytes;
        values(j, point, whole, o);
        o += whole * bytes, b += whole * bytes, point += whole;
        if (b < to) { // the start of a value the next piece ends
          values(j, point, 1, value.data());
          std::memcpy(o, value.data(), to - b);
        }
      }
      plane = plane_end;
    }
  }
};

/// The bytes of the layout each piece of the body holds; LZF's window is 8 KiB: the ratio barely changes.
constexpr std::size_t kPieceBytes = std::size_t{1} << 20;
/// The header line of a body of several pieces: the bytes each unpacks to, then each one's
/// compressed size, so that a reader can decompress them side by side.
constexpr char kPiecesTag[] = "# msfusion lzf_pieces";

/// LZF's stream of the layout (pcl::lzfCompress), compressed in pieces of kPieceBytes on every
/// core. LZF refers back only within what its stream wrote, so the pieces' streams one after
/// another are one stream that any LZF reader (PCL's) decompresses whole; a body of one piece
/// is PCL's own. Pieces of a fixed size: the same bytes on any number of threads.
std::vector<std::vector<char>> compressInPieces(const FieldsSideBySide& layout) {
  const std::size_t bytes = layout.bytes(), pieces = (bytes + kPieceBytes - 1) / kPieceBytes;
  std::vector<std::vector<char>> compressed(pieces);
  parallelFor(cv::Range(0, static_cast<int>(pieces)), [&](const cv::Range& range) {
    // Each piece keeps only its compressed bytes: the room LZF may need is the task's, once.
    std::vector<char> piece(kPieceBytes), room(kPieceBytes * 3 / 2 + 16);
    for (int k = range.start; k < range.end; ++k) {
      const std::size_t start = static_cast<std::size_t>(k) * kPieceBytes;
      const std::size_t length = std::min(kPieceBytes, bytes - start);
      layout.copy(start, start + length, piece.data());
      const unsigned int written = pcl::lzfCompress(piece.data(), static_cast<unsigned int>(length), room.data(),
                                                    static_cast<unsigned int>(length * 3 / 2 + 16));
      compressed[static_cast<std::size_t>(k)].assign(room.data(), room.data() + written); // 0: it did not compress
    }
  });
  for (const std::vector<char>& piece : compressed)
    if (piece.empty())
      throw IOError("its " + std::to_string(bytes) + " bytes do not compress");
  return compressed;
}

/// The bytes of the body of `layout`'s points, when the format's 32-bit sizes hold them (the
/// compressed body may need half as much again).
std::size_t bodyBytes(const pcl::PCLPointCloud2& layout) {
  const std::size_t points = static_cast<std::size_t>(layout.width) * layout.height;
  std::size_t point_bytes = 0;
  for (const FieldPlane& f : fieldPlanes(layout))
    point_bytes += f.bytes;
  const std::size_t bytes = points * point_bytes;
  constexpr std::size_t kMaxBytes = std::numeric_limits<std::uint32_t>::max() / 3 * 2;
  if (bytes > kMaxBytes)
    throw IOError("its " + std::to_string(points) + " points of " + std::to_string(point_bytes) + " bytes make " +
                  std::to_string(bytes) + " bytes, more than a binary_compressed .pcd holds (" +
                  std::to_string(kMaxBytes) + ": its sizes are 32-bit)");
  return bytes;
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

/// The kPiecesTag line of a body of several pieces; none for one piece, whose file is PCL's own.
std::string piecesLine(const std::vector<std::vector<char>>& pieces) {
  if (pieces.size() < 2)
    return "";
  std::string line = std::string(kPiecesTag) + " " + std::to_string(kPieceBytes);
  for (const std::vector<char>& piece : pieces)
    line += " " + std::to_string(piece.size());
  return line + "\n";
}

/// Where a body's pieces lie, as its header's kPiecesTag line says; no sizes without one.
struct Pieces {
  std::size_t unpacked_bytes = 0; ///< of each piece but the last
  std::vector<std::size_t> sizes; ///< compressed, in the body's order

  static Pieces of(const std::string& header) {
    std::istringstream lines(header);
    for (std::string line; std::getline(lines, line) && line.rfind("DATA", 0) != 0;) {
      if (line.rfind(kPiecesTag, 0) != 0)
        continue;
      std::istringstream words(line.substr(sizeof(kPiecesTag) - 1));
      words.imbue(std::locale::classic());
      Pieces pieces;
      words >> pieces.unpacked_bytes;
      for (std::size_t size = 0; words >> size;)
        pieces.sizes.push_back(size);
      return pieces;
    }
    return {};
  }

  /// Whether they make up a body of `compressed` bytes that unpacks to `unpacked`: together
  /// the pieces' shares cover every byte once.
  bool fit(std::size_t compressed, std::size_t unpacked) const {
    if (unpacked_bytes == 0 || sizes.size() != unpacked / unpacked_bytes + (unpacked % unpacked_bytes != 0))
      return false;
    std::size_t left = compressed;
    for (std::size_t size : sizes) {
      if (size > left)
        return false;
      left -= size;
    }
    return left == 0;
  }
};

/// Bytes not set to zero first: each is written once, by the core that unpacks its piece.
struct Buffer {
  std::unique_ptr<char[]> bytes;
  std::size_t size;
  explicit Buffer(std::size_t n) : bytes(new char[n]), size(n) {}
  char* data() const { return bytes.get(); }
};

/// The pieces of `body` unpacked side by side into `layout` (of the bytes the pieces unpack
/// to); false when one does not unpack to its share.
bool decompressPieces(const Buffer& body, const Pieces& pieces, const Buffer& layout) {
  std::vector<std::size_t> starts(pieces.sizes.size(), 0);
  for (std::size_t k = 1; k < starts.size(); ++k)
    starts[k] = starts[k - 1] + pieces.sizes[k - 1];
  std::atomic<bool> whole{true};
  parallelFor(cv::Range(0, static_cast<int>(starts.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const std::size_t out = k * pieces.unpacked_bytes, length = std::min(pieces.unpacked_bytes, layout.size - out);
      if (pcl::lzfDecompress(body.data() + starts[k], static_cast<unsigned int>(pieces.sizes[k]), layout.data() + out,
                             static_cast<unsigned int>(length)) != length)
        whole = false;
    }
  });
  return whole;
}

/// Whether every value of a field's plane is finite; a field of whole numbers always is.
bool allFinite(const char* plane, std::size_t values, std::uint8_t datatype) {
  auto finite = [&](auto zero) {
    for (std::size_t i = 0; i < values; ++i) {
      decltype(zero) value;
      std::memcpy(&value, plane + i * sizeof value, sizeof value);
      if (!std::isfinite(value))
        return false;
    }
    return true;
  };
  if (datatype == pcl::PCLPointField::FLOAT32)
    return finite(0.f);
  return datatype != pcl::PCLPointField::FLOAT64 || finite(0.0);
}

/// The fields' planes (x x x ... y y y ...) laid out as whole points in `blob`, on every core,
/// with is_dense as PCL's reader sets it: false when a value is not finite.
void scatterPlanes(const Buffer& layout, pcl::PCLPointCloud2& blob) {
  const std::size_t points = static_cast<std::size_t>(blob.width) * blob.height;
  const std::vector<FieldPlane> fields = fieldPlanes(blob);
  std::vector<std::size_t> starts(fields.size(), 0);
  for (std::size_t j = 1; j < fields.size(); ++j)
    starts[j] = starts[j - 1] + fields[j - 1].bytes * points;
  constexpr std::size_t kChunk = 1 << 16; // points of one task
  std::atomic<bool> dense{true};
  parallelFor(cv::Range(0, static_cast<int>((points + kChunk - 1) / kChunk)), [&](const cv::Range& range) {
    for (std::size_t first = range.start * kChunk; first < std::min(points, range.end * kChunk); first += kChunk) {
      const std::size_t n = std::min(kChunk, points - first);
      for (std::size_t j = 0; j < fields.size(); ++j) {
        const std::size_t bytes = fields[j].bytes;
        const char* in = layout.data() + starts[j] + first * bytes;
        std::uint8_t* out = blob.data.data() + first * blob.point_step + fields[j].offset;
        copyValues(reinterpret_cast<const std::uint8_t*>(in), bytes, out, blob.point_step, bytes, n);
        if (!allFinite(layout.data() + starts[j] + first * bytes, n * blob.fields[j].count, blob.fields[j].datatype))
          dense = false;
      }
    }
  });
  blob.is_dense = dense;
}

} // namespace

void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin,
                        const Eigen::Quaternionf& orientation, const std::string& comment) {
  writeCompressedPcd(out, blob, blob.data.data(), blob.data.size(), origin, orientation, comment);
}

void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& layout, const std::uint8_t* data,
                        std::size_t data_bytes, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                        const std::string& comment) {
  const std::size_t points = static_cast<std::size_t>(layout.width) * layout.height;
  bodyBytes(layout); // too many points are named as such, whatever the data
  if (data_bytes < points * layout.point_step)
    throw IOError("its data holds " + std::to_string(data_bytes) + " bytes, not its " +
                  std::to_string(points) + " points of " + std::to_string(layout.point_step));
  const std::vector<FieldPlane> fields = fieldPlanes(layout);
  const std::size_t step = layout.point_step;
  const FieldValues values = [&](std::size_t field, std::size_t first, std::size_t count, char* to) {
    copyValues(data + first * step + fields[field].offset, step, reinterpret_cast<std::uint8_t*>(to),
               fields[field].bytes, fields[field].bytes, count);
  };
  writeCompressedPcd(out, layout, values, origin, orientation, comment);
}

void writeCompressedPcd(std::ostream& out, const pcl::PCLPointCloud2& layout, const FieldValues& values,
                        const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                        const std::string& comment) {
  const std::vector<FieldPlane> fields = fieldPlanes(layout);
  const std::size_t points = static_cast<std::size_t>(layout.width) * layout.height, bytes = bodyBytes(layout);
  const FieldsSideBySide body{values, points, fields};
  const std::vector<std::vector<char>> pieces = compressInPieces(body);
  std::size_t compressed = 0;
  for (const std::vector<char>& piece : pieces)
    compressed += piece.size();
  if (compressed > std::numeric_limits<std::uint32_t>::max())
    throw IOError("its " + std::to_string(bytes) + " bytes compress to more than the format's 32-bit sizes hold");
  const std::uint32_t sizes[2] = {static_cast<std::uint32_t>(compressed), static_cast<std::uint32_t>(bytes)};
  const std::string text = header(layout, origin, orientation, comment + piecesLine(pieces));
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.write(reinterpret_cast<const char*>(sizes), sizeof sizes);
  for (const std::vector<char>& piece : pieces)
    out.write(piece.data(), static_cast<std::streamsize>(piece.size()));
}

bool readCompressedPieces(const std::string& path, std::size_t data_index, pcl::PCLPointCloud2& blob) {
  std::size_t point_bytes = 0;
  for (const pcl::PCLPointField& field : blob.fields) {
    if (field.name == "_")
      return false; // padding: PCL's reader handles it
    point_bytes += static_cast<std::size_t>(field.count) * pcl::getFieldSize(field.datatype);
  }
  std::ifstream in(path, std::ios::binary);
  std::string header(data_index, '\0');
  std::uint32_t sizes[2] = {0, 0}; // compressed, unpacked
  if (!in.read(header.data(), static_cast<std::streamsize>(data_index)) ||
      !in.read(reinterpret_cast<char*>(sizes), sizeof sizes))
    return false;
  const Pieces pieces = Pieces::of(header);
  const std::size_t points = static_cast<std::size_t>(blob.width) * blob.height;
  if (point_bytes != blob.point_step || sizes[1] != points * point_bytes || blob.data.size() != sizes[1] ||
      !pieces.fit(sizes[0], sizes[1]))
    return false;
  const Buffer body(sizes[0]), layout(sizes[1]);
  if (!in.read(body.data(), static_cast<std::streamsize>(body.size)) || !decompressPieces(body, pieces, layout))
    return false;
  scatterPlanes(layout, blob);
  return true;
}

} // namespace msf
