// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/checked_write.h>
#include <msf/io/impl/cloud_io.hpp>
#include <msf/io/compressed_pcd.h>

#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <pcl/io/obj_io.h>
#include <pcl/io/vtk_io.h>
#include <pcl/io/vtk_lib_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <vector>

namespace msf {

namespace {
/// LZF's largest ratio is a 264-byte match in 3 bytes; 100 bounds it.
constexpr std::uint64_t kMaxCompressionRatio = 100;

/// The bytes of a PLY scalar type PCL's parser knows, 0 for any other word.
std::uint64_t plyTypeSize(const std::string& type) {
  static const std::pair<const char*, std::uint64_t> kTypes[] = {
      {"char", 1},   {"int8", 1},   {"uchar", 1},  {"uint8", 1},  {"short", 2},   {"int16", 2},
      {"ushort", 2}, {"uint16", 2}, {"int", 4},    {"int32", 4},  {"uint", 4},    {"uint32", 4},
      {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
  for (const auto& t : kTypes)
    if (type == t.first)
      return t.second;
  return 0;
}

/// The count types of a PLY list PCL's parser takes.
bool plyListCountType(const std::string& type) {
  for (const char* t : {"uchar", "uint8", "ushort", "uint16", "uint", "uint32", "int", "int32"})
    if (type == t)
      return true;
  return false;
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

/// `needed` counts what the header declares up to and with these `count` items; `noun` is
/// what the file is to the caller ("cloud", "mesh").
[[noreturn]] void tooManyPoints(const std::string& path, const std::string& what, std::uint64_t count,
                                double needed, std::uintmax_t available, const std::string& noun = "cloud") {
  char bytes[32];
  std::snprintf(bytes, sizeof bytes, "%.0f", needed);
  throw IOError(noun + " '" + path + "' declares " + std::to_string(count) + " " + what + " in its header, " +
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

/// A binary_compressed body starts with two sizes that PCL's reader takes on trust: an
/// uncompressed size other than the header's points x point step resizes the cloud, and the
/// header's worth of points is then copied out of the smaller buffer (fuzz_cloud: a SEGV
/// for a size of 0); a compressed size beyond the file makes LZF read past it.
void checkCompressedSizes(const std::string& path, const pcl::PCLPointCloud2& header, unsigned int data_index) {
  const std::uintmax_t size = fileSize(path);
  const std::uintmax_t available = size > data_index ? size - data_index : 0;
  if (available < 8)
    throw IOError("cloud '" + path + "': its binary_compressed body has " + std::to_string(available) +
                  " bytes, not even the 8 of its two sizes (a truncated file)");
  char bytes[8];
  std::ifstream in(path, std::ios::binary);
  in.seekg(data_index);
  if (!in.read(bytes, sizeof bytes))
    throw IOError("'" + path + "' cannot be read");
  std::uint32_t compressed = 0, uncompressed = 0; // in the host's order, as PCL reads them
  std::memcpy(&compressed, bytes, 4);
  std::memcpy(&uncompressed, bytes + 4, 4);
  if (compressed > available - 8)
    throw IOError("cloud '" + path + "': its binary_compressed body says " + std::to_string(compressed) +
                  " bytes of compressed data, but the file has " + std::to_string(available - 8) +
                  " after the sizes (a truncated file)");
  const std::uint64_t expected = static_cast<std::uint64_t>(header.width) * header.height * header.point_step;
  if (uncompressed != expected)
    throw IOError("cloud '" + path + "': its binary_compressed body says it unpacks to " +
                  std::to_string(uncompressed) + " bytes, but the header's " +
                  std::to_string(static_cast<std::uint64_t>(header.width) * header.height) + " points of " +
                  std::to_string(header.point_step) + " bytes make " + std::to_string(expected) +
                  " (a damaged file)");
}

/// A header line for a message: printable, at most 60 characters.
std::string shownLine(const std::string& line) {
  std::string shown;
  for (char c : line.substr(0, 60))
    shown += c >= 0x20 && c < 0x7f ? c : '?';
  return line.size() > 60 ? shown + "..." : shown;
}

/// The words of a header line, split at any of `separators`.
std::vector<std::string> wordsOf(const std::string& line, const char* separators) {
  std::vector<std::string> words;
  std::string word;
  for (char c : line + ' ') {
    if (c == ' ' || (c != '\0' && std::strchr(separators, c))) { // strchr finds the NUL that ends `separators`
      if (!word.empty())
        words.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  return words;
}

/// The whole of `token` as an integer in [low, high], or -1.
long long headerInteger(const std::string& token, long long low, long long high) {
  if (token.empty() || token.size() > 19)
    return -1;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(token.c_str(), &end, 10);
  return *end == '\0' && errno == 0 && v >= low && v <= high ? v : -1;
}

/// The keywords PCL's PCDReader::readHeader acts on. It matches them as prefixes of a line's
/// first word ("SIZE`" is SIZE to it) and reads on after DATA; it sizes the cloud's data
/// (POINTS x the point step, 4 GB for a 1.2 KB file found by fuzz/fuzz_cloud) as soon as it
/// meets POINTS, DATA or not.
constexpr const char* kPcdKeywords[] = {"VERSION", "FIELDS", "COLUMNS", "SIZE",   "TYPE", "COUNT",
                                        "WIDTH",   "HEIGHT", "VIEWPOINT", "POINTS", "DATA"};

/// After the DATA line, PCL goes on reading lines as header lines until one is not: empty
/// lines, comments and VERSION are passed over, a line starting with another keyword would
/// change the header it checked. Returns that line's first characters ("" when PCL stops).
/// Reads the lines by character, never a whole binary body into memory.
std::string keywordLineAfterData(std::istream& in) {
  std::streambuf& buf = *in.rdbuf();
  using Traits = std::char_traits<char>;
  for (;;) {
    int c = buf.sgetc();
    if (c == Traits::eof())
      return "";
    if (c == '\n') { // an empty line: PCL passes over it
      buf.sbumpc();
      continue;
    }
    std::string head;
    while (c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f') // what PCL's trim removes
      c = buf.snextc();
    while (c != Traits::eof() && c != '\n' && head.size() < 32) {
      head += static_cast<char>(c);
      c = buf.snextc();
    }
    if (head.empty())
      return ""; // a line of blanks: PCL stops
    if (head[0] == '#' || head.rfind("VERSION", 0) == 0) {
      while (c != Traits::eof() && c != '\n')
        c = buf.snextc();
      continue;
    }
    for (const char* keyword : kPcdKeywords)
      if (head.rfind(keyword, 0) == 0)
        return head;
    return "";
  }
}

/// A .pcd header read strictly, line by line up to DATA: each line one of the format's
/// keywords, once, with whole numbers in range and one value per field.
class PcdHeader {
public:
  explicit PcdHeader(const std::string& path) : path_(path) {}

  /// Reads and checks the lines up to DATA's; throws IOError naming the first bad one.
  void read(std::istream& in) {
    while (data_type_ < 0) {
      if (bytes_ >= (1u << 16) || !std::getline(in, line_))
        throw IOError("cloud '" + path_ + "' is not a valid .pcd file (bad header): no DATA line" +
                      (bytes_ >= (1u << 16) ? " in its first 65536 bytes" : std::string()));
      ++line_no_;
      bytes_ += line_.size() + 1;
      if (line_.empty())
        continue;
      const std::vector<std::string> words = wordsOf(line_, " \t\r"); // PCL's separators
      if (words.empty())
        bad("a line of blanks");
      std::string key = words[0];
      if (key[0] == '#')
        continue;
      if (key == "COLUMNS")
        key = "FIELDS";
      if (std::find(std::begin(kPcdKeywords), std::end(kPcdKeywords), key) == std::end(kPcdKeywords))
        bad("not a header keyword (VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA)");
      if (!seen_.insert(key).second)
        bad(key + " given twice");
      readKeyword(key, std::vector<std::string>(words.begin() + 1, words.end()));
    }
  }

  /// 0 ascii, 1 binary, 2 binary_compressed.
  int dataType() const { return data_type_; }
  /// The header's bytes, DATA's line included.
  std::size_t bytes() const { return bytes_; }

  /// The fields and the most points any reading of the header gives, as checkPcdBody sizes
  /// the body from them.
  pcl::PCLPointCloud2 bodyLayout() const {
    const double n = std::max(static_cast<double>(std::max(width_, 0LL)) * static_cast<double>(std::max(height_, 1LL)),
                              static_cast<double>(points_));
    pcl::PCLPointCloud2 layout;
    layout.width = static_cast<std::uint32_t>(std::min(n, 4e9));
    layout.height = 1;
    for (std::size_t i = 0; i < fields_; ++i) {
      const std::uint64_t size = i < sizes_.size() ? sizes_[i] : 4;
      if (i < counts_.size() && counts_[i] == 0)
        continue; // no value in the body (PCL drops the field)
      pcl::PCLPointField f;
      f.datatype = size == 1 ? pcl::PCLPointField::UINT8 : size == 2 ? pcl::PCLPointField::UINT16
                 : size == 8 ? pcl::PCLPointField::FLOAT64 : pcl::PCLPointField::FLOAT32;
      f.count = static_cast<std::uint32_t>(i < counts_.size() ? counts_[i] : 1);
      layout.fields.push_back(f);
    }
    return layout;
  }

private:
  [[noreturn]] void bad(const std::string& why) const {
    throw IOError("cloud '" + path_ + "' is not a valid .pcd file (bad header): line " + std::to_string(line_no_) +
                  " '" + shownLine(line_) + "': " + why);
  }

  void readKeyword(const std::string& key, const std::vector<std::string>& values) {
    if (key == "FIELDS") {
      if (values.empty())
        bad("no field");
      fields_ = values.size();
    } else if (key == "SIZE") {
      readSizes(key, values);
    } else if (key == "TYPE") {
      readTypes(key, values);
    } else if (key == "COUNT") {
      readCounts(key, values);
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      readDimension(key, values);
    } else if (key == "VIEWPOINT") {
      if (values.size() != 7)
        bad("VIEWPOINT takes 7 numbers (tx ty tz qw qx qy qz)");
    } else if (key == "DATA") {
      readData(values);
    }
  }

  /// A line of one value per field, after FIELDS and the line `before` when not null.
  void requireOnePerField(const std::string& key, const std::vector<std::string>& values, const char* before) const {
    if (fields_ == 0 || (before && !seen_.count(before)))
      bad(key + " before " + (fields_ == 0 ? "FIELDS" : before));
    if (values.size() != fields_)
      bad(std::to_string(values.size()) + " values for " + std::to_string(fields_) + " fields");
  }

  void readSizes(const std::string& key, const std::vector<std::string>& values) {
    requireOnePerField(key, values, nullptr);
    for (const auto& v : values) {
      const long long size = headerInteger(v, 1, 8);
      if (size != 1 && size != 2 && size != 4 && size != 8)
        bad("size '" + shownLine(v) + "' is not 1, 2, 4 or 8");
      sizes_.push_back(static_cast<std::uint64_t>(size));
    }
  }

  void readTypes(const std::string& key, const std::vector<std::string>& values) const {
    requireOnePerField(key, values, "SIZE");
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::string& v = values[i];
      if (v != "F" && v != "I" && v != "U")
        bad("type '" + shownLine(v) + "' is not F, I or U");
      if (v == "F" && sizes_[i] != 4 && sizes_[i] != 8)
        bad("field " + std::to_string(i + 1) + " is F of size " + std::to_string(sizes_[i]) + " (4 or 8)");
    }
  }

  void readCounts(const std::string& key, const std::vector<std::string>& values) {
    requireOnePerField(key, values, "TYPE");
    for (const auto& v : values) {
      const long long count = headerInteger(v, 0, 1 << 20);
      if (count < 0)
        bad("count '" + shownLine(v) + "' is not a whole number 0 .. 1048576");
      counts_.push_back(static_cast<std::uint64_t>(count));
    }
  }

  /// WIDTH, HEIGHT or POINTS.
  void readDimension(const std::string& key, const std::vector<std::string>& values) {
    if (values.size() != 1)
      bad(key + " takes one number");
    const long long v = headerInteger(values[0], 0, std::numeric_limits<std::int32_t>::max());
    if (v < 0)
      bad("'" + shownLine(values[0]) + "' is not a whole number 0 .. 2147483647");
    if (key == "POINTS" && fields_ == 0)
      bad("POINTS before FIELDS");
    (key == "WIDTH" ? width_ : key == "HEIGHT" ? height_ : points_) = v;
  }

  void readData(const std::vector<std::string>& values) {
    if (values.size() != 1 || (values[0] != "ascii" && values[0] != "binary" && values[0] != "binary_compressed"))
      bad("DATA is ascii, binary or binary_compressed");
    if (!seen_.count("SIZE") || !seen_.count("TYPE"))
      bad(std::string("DATA before ") + (seen_.count("SIZE") ? "TYPE" : "SIZE") +
          " (without both, PCL takes every field for a 4-byte float whatever its size)");
    data_type_ = values[0] == "ascii" ? 0 : values[0] == "binary" ? 1 : 2;
  }

  std::string path_;
  std::string line_; // the line being read, for the messages
  std::size_t fields_ = 0, bytes_ = 0, line_no_ = 0;
  std::vector<std::uint64_t> sizes_, counts_;
  std::set<std::string> seen_;
  long long width_ = -1, height_ = -1, points_ = -1;
  int data_type_ = -1;
};

/// PCL's readHeader sizes the cloud's data from the header before anything checks it (12 GB
/// for POINTS 1e9): the header is read here first, strictly (PcdHeader), and its counts
/// checked against the file's size, so that what PCL then reads is what was checked.
void checkPcdHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  PcdHeader header(path);
  header.read(in);
  const std::string after = keywordLineAfterData(in);
  if (!after.empty())
    throw IOError("cloud '" + path + "' is not a valid .pcd file (bad header): a line after DATA starts with '" +
                  shownLine(after) + "', which PCL would read as a header line");
  checkPcdBody(path, header.bodyLayout(), header.dataType(), static_cast<unsigned int>(header.bytes()), true);
}

/// A .ply header read strictly, line by line up to end_header: the magic line, each line one
/// of the format's keywords, one format, counts whole numbers, known property types, no
/// duplicates. `what` is "cloud" or "mesh", for the messages.
class PlyHeader {
public:
  PlyHeader(const std::string& path, const std::string& what) : path_(path), what_(what) {}

  /// Reads and checks the lines up to end_header; throws IOError naming the first bad one.
  void read(std::istream& in) {
    while (!ended_) {
      if (bytes_ >= (1u << 16) || !std::getline(in, line_))
        throw IOError(what_ + " '" + path_ + "' is not a valid .ply file (bad header): no end_header line" +
                      (bytes_ >= (1u << 16) ? " in its first 65536 bytes" : std::string()));
      ++line_no_;
      bytes_ += line_.size() + 1;
      if (line_no_ == 1) {
        // PCL takes "ply\r" for a file of CR LF lines, and then every line ends in CR LF.
        crlf_ = line_ == "ply\r";
        if (line_ != "ply" && !crlf_)
          bad("the first line is not 'ply'");
        continue;
      }
      takeLineEnd();
      const std::vector<std::string> words = wordsOf(line_, " \t\v\f"); // isspace, less the CR taken off
      if (words.empty())
        continue; // PCL passes over a line of blanks
      // PCL's reader splits an obj_info line at blanks and asserts that the first word is
      // obj_info: a blank before it aborts the program (fuzz/fuzz_cloud).
      if (std::strchr(" \t\v\f", line_[0]))
        bad("a line that starts with a blank");
      readKeyword(words);
    }
    if (format_.empty())
      bad("no format line before end_header");
  }

  /// PCL's own files: obj_info's num_cols x num_rows is the vertex count (a dense cloud) or
  /// the range_grid's.
  void checkGrid() const {
    if (grid_cols_ == 0 || grid_rows_ == 0)
      return;
    const std::uint64_t cells = grid_cols_ * grid_rows_;
    const std::uint64_t vertices = count("vertex"), range_grid = count("range_grid");
    if (cells != vertices && cells != range_grid)
      throw IOError(what_ + " '" + path_ + "' is not a valid .ply file (bad header): obj_info num_cols " +
                    std::to_string(grid_cols_) + " x num_rows " + std::to_string(grid_rows_) + " make " +
                    std::to_string(cells) + " points, not its " + std::to_string(vertices) + " vertices" +
                    (range_grid ? " nor its " + std::to_string(range_grid) + " range_grid items" : std::string()));
  }

  /// The elements' smallest body against the file's size.
  void checkBodySize() const {
    const std::uintmax_t size = fileSize(path_);
    const std::uintmax_t available = size > bytes_ ? size - bytes_ : 0;
    const bool ascii = format_ == "ascii";
    double needed = 0;
    for (const auto& e : elements_) {
      if (e.count > 0 && e.properties.empty())
        throw IOError(what_ + " '" + path_ + "' is not a valid .ply file (bad header): element '" +
                      shownLine(e.name) + "' has " + std::to_string(e.count) + " items but no property");
      // An ascii item is a line of its values, each followed by a blank or the line's end.
      needed += static_cast<double>(e.count) * static_cast<double>(ascii ? 2 * e.values : e.bytes);
      if (needed > static_cast<double>(available) + (ascii ? 1 : 0)) // the last line may lack its end
        tooManyPoints(path_, e.name + " elements", e.count, needed, available, what_);
    }
  }

private:
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::uint64_t bytes = 0;  // of one item in a binary body, each list empty
    std::uint64_t values = 0; // of one item in an ascii body, each list empty
    std::set<std::string> properties;
  };

  [[noreturn]] void bad(const std::string& why) const {
    throw IOError(what_ + " '" + path_ + "' is not a valid .ply file (bad header): line " + std::to_string(line_no_) +
                  " '" + shownLine(line_) + "': " + why);
  }

  /// Takes the CR of a CR LF file off the line; a CR anywhere else is an error.
  void takeLineEnd() {
    if (crlf_) {
      if (line_.empty() || line_.back() != '\r')
        bad("a line that does not end in CR LF as the first line does");
      line_.pop_back();
    }
    if (line_.find('\r') != std::string::npos)
      bad(crlf_ ? "a CR inside a line" : "a CR in a file whose first line ends in LF only");
  }

  void readKeyword(const std::vector<std::string>& words) {
    const std::string& key = words[0];
    if (key == "comment")
      return;
    if (key == "obj_info") {
      readObjInfo(words);
    } else if (key == "end_header") {
      if (words.size() != 1)
        bad("end_header takes nothing after it");
      ended_ = true;
    } else if (key == "format") {
      readFormat(words);
    } else if (key == "element") {
      readElement(words);
    } else if (key == "property") {
      readProperty(words);
    } else {
      bad("not a header keyword (format, element, property, comment, obj_info, end_header)");
    }
  }

  /// num_cols x num_rows size the cloud's data before any vertex is read (atoi: a number past
  /// int is undefined), so they are checked against the elements (checkGrid).
  void readObjInfo(const std::vector<std::string>& words) {
    if (words.size() < 3 || (words[1] != "num_cols" && words[1] != "num_rows"))
      return;
    const long long v = headerInteger(words[2], 0, std::numeric_limits<std::int32_t>::max());
    if (v < 0 || words[2].find_first_not_of("0123456789") != std::string::npos)
      bad(words[1] + " '" + shownLine(words[2]) + "' is not a whole number 0 .. 2147483647");
    (words[1] == "num_cols" ? grid_cols_ : grid_rows_) = static_cast<std::uint64_t>(v);
  }

  void readFormat(const std::vector<std::string>& words) {
    if (!format_.empty())
      bad("format given twice");
    if (words.size() != 3 ||
        (words[1] != "ascii" && words[1] != "binary_little_endian" && words[1] != "binary_big_endian") ||
        words[2] != "1.0")
      bad("format is ascii, binary_little_endian or binary_big_endian, version 1.0");
    format_ = words[1];
  }

  void readElement(const std::vector<std::string>& words) {
    if (words.size() != 3)
      bad("element takes a name and a count");
    const long long count = headerInteger(words[2], 0, std::numeric_limits<std::int32_t>::max());
    if (count < 0 || words[2].find_first_not_of("0123456789") != std::string::npos)
      bad("count '" + shownLine(words[2]) + "' is not a whole number 0 .. 2147483647");
    for (const auto& e : elements_)
      if (e.name == words[1])
        bad("element '" + shownLine(words[1]) + "' given twice");
    elements_.push_back({words[1], static_cast<std::uint64_t>(count), 0, 0, {}});
  }

  void readProperty(const std::vector<std::string>& words) {
    if (elements_.empty())
      bad("property before any element");
    Element& e = elements_.back();
    const bool list = words.size() > 1 && words[1] == "list";
    if (words.size() != (list ? 5u : 3u))
      bad(list ? "property list takes a count type, a value type and a name" : "property takes a type and a name");
    const std::string& type = words[list ? 2 : 1];
    if (list && !plyListCountType(type))
      bad("type '" + shownLine(type) +
          "' is not a list's count type (uchar, ushort, uint, int or their sized names)");
    const std::string& scalar = words[list ? 3 : 1];
    if (plyTypeSize(scalar) == 0)
      bad("type '" + shownLine(scalar) + "' is not a PLY scalar type (char, uchar, short, ushort, int, uint, float, "
          "double or their sized names)");
    const std::uint64_t size = plyTypeSize(type);
    if (!e.properties.insert(words.back()).second)
      bad("property '" + shownLine(words.back()) + "' given twice in element '" + shownLine(e.name) + "'");
    e.bytes += size; // a list holds at least its count
    ++e.values;
  }

  /// The count of the element `name`, 0 when there is none.
  std::uint64_t count(const char* name) const {
    for (const auto& e : elements_)
      if (e.name == name)
        return e.count;
    return 0;
  }

  std::string path_, what_;
  std::string line_; // the line being read, for the messages
  std::size_t bytes_ = 0, line_no_ = 0;
  std::vector<Element> elements_;
  std::string format_;
  bool crlf_ = false, ended_ = false;
  std::uint64_t grid_cols_ = 0, grid_rows_ = 0; // obj_info num_cols, num_rows
};

/// PCL's PLY parser reads an element's count into a std::size_t with operator>>, which takes
/// "-7" for 2^64 - 7 and sizes the cloud's data from it (52 GB for `element vertex -7`, found
/// by fuzz/fuzz_cloud), and passes over lines it does not know. The header is read here first,
/// strictly (PlyHeader), and the elements' smallest body checked against the file's size, so
/// that what PCL then reads is what was checked. `what` is "cloud" or "mesh", for the messages.
void checkPlyHeader(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  PlyHeader header(path, what);
  header.read(in);
  header.checkGrid();
  header.checkBodySize();
}

/// Each field within the point as PCL laid it out from the header: a SIZE that disagreed with
/// the TYPE (no TYPE: PCL takes 4-byte floats) made pcl::fromPCLPointCloud2 read past the
/// cloud's data (fuzz/fuzz_cloud, a heap-buffer-overflow).
void checkFieldLayout(const std::string& path, const pcl::PCLPointCloud2& blob) {
  for (const auto& f : blob.fields) {
    const std::uint64_t size = pcl::getFieldSize(f.datatype);
    if (size == 0)
      throw IOError("cloud '" + path + "': field '" + shownLine(f.name) + "' has no valid type");
    if (f.offset + static_cast<std::uint64_t>(f.count) * size > blob.point_step)
      throw IOError("cloud '" + path + "': field '" + shownLine(f.name) + "' (" + std::to_string(f.count) + " x " +
                    std::to_string(size) + " bytes at byte " + std::to_string(f.offset) + ") does not fit in its " +
                    std::to_string(blob.point_step) + "-byte point: SIZE and TYPE disagree");
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
      checkFieldLayout(path, blob);
      checkPcdBody(path, blob, data_type, data_index, false); // the values were checked above
      if (data_type == 2)
        checkCompressedSizes(path, blob, data_index);
      const bool in_pieces = data_type == 2 && readCompressedPieces(path, data_index, blob);
      result = in_pieces ? 0 : reader.read(path, blob);
    } else if (ext == ".ply") {
      checkPlyHeader(path, "cloud");
      result = pcl::PLYReader().read(path, blob);
      // A camera element's viewport in the body resizes the cloud after its data was sized.
      if (result >= 0 && blob.data.size() != static_cast<std::uint64_t>(blob.width) * blob.height * blob.point_step)
        throw IOError("cloud '" + path + "': its " + std::to_string(blob.data.size()) + " bytes of points are not " +
                      std::to_string(blob.width) + " x " + std::to_string(blob.height) + " points of " +
                      std::to_string(blob.point_step) + " bytes (a camera viewport that contradicts the header?)");
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

void saveCloudBlob(const std::string& path, const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin,
                   const Eigen::Quaternionf& orientation) {
  detail::saveCloudData(path, blob, blob.data.data(), blob.data.size(), origin, orientation);
}

void detail::saveCloudData(const std::string& path, const pcl::PCLPointCloud2& layout, const std::uint8_t* data,
                           std::size_t bytes, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation) {
  const std::string ext = fileExtension(path);
  if (ext != ".pcd" && ext != ".ply")
    throw IOError("cannot write '" + path + "': a cloud is written as .pcd or .ply");
  if (ext == ".ply") {
    // PCL's PLY writer takes a PCLPointCloud2: the points are copied in unless they are its own.
    pcl::PCLPointCloud2 copy;
    if (layout.data.data() != data) {
      copy = layout;
      copy.data.assign(data, data + bytes);
    }
    const pcl::PCLPointCloud2& blob = layout.data.data() == data ? layout : copy;
    writeThroughPipeAtomically(path, [&](const std::string& sink) {
      if (pcl::PLYWriter().write(sink, blob, origin, orientation, true, false) != 0)
        throw IOError("cannot write cloud '" + path + "'");
    });
    return;
  }
  writeStreamAtomically(path, [&](std::ostream& out) {
    try {
      writeCompressedPcd(out, layout, data, bytes, origin, orientation);
    } catch (const IOError& e) { // checked before a byte is written; the atomic write leaves no file
      throw IOError("cannot write '" + path + "': " + e.what());
    }
  });
}

void requireMeshExtension(const std::string& path) {
  const std::string ext = fileExtension(path);
  if (ext != ".ply" && ext != ".obj" && ext != ".vtk")
    throw IOError("cannot write mesh '" + path + "': use .ply, .obj or .vtk");
}

void saveMesh(const std::string& path, const pcl::PolygonMesh& mesh) {
  requireMeshExtension(path);
  const std::string ext = fileExtension(path);
  if (mesh.cloud.width == 0 || mesh.cloud.height == 0) // PCL's writers refuse it, saying why on the console only
    throw InvalidInputError("cannot write mesh '" + path + "': it has no vertices");
  writeThroughPipeAtomically(path, [&](const std::string& sink) {
    int result = -1;
    if (ext == ".ply")
      result = pcl::io::savePLYFileBinary(sink, mesh);
    else if (ext == ".obj")
      result = pcl::io::saveOBJFile(sink, mesh);
    else
      result = pcl::io::saveVTKFile(sink, mesh);
    if (result != 0)
      throw IOError("cannot write mesh '" + path + "'");
  });
}

void loadMesh(const std::string& path, pcl::PolygonMesh& mesh) {
  requireFile(path, "mesh");
  const std::string ext = fileExtension(path);
  int result = -1;
  if (ext == ".ply") {
    checkPlyHeader(path, "mesh");
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
  template void fromCloudBlob<T>(pcl::PCLPointCloud2, pcl::PointCloud<T>&, const std::string&); \
  template void saveCloud<T>(const std::string&, const pcl::PointCloud<T>&);
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZ)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZI)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZRGB)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointXYZRGBA)
MSF_INSTANTIATE_CLOUD_IO(pcl::PointNormal)

} // namespace msf
