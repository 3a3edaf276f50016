// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/field_conversion.h>

#include <pcl/common/io.h> // pcl::getFieldSize

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

namespace msf {

namespace {

using Field = pcl::PCLPointField;

template <typename T> double load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

double readValue(const std::uint8_t* p, std::uint8_t type) {
  switch (type) {
  case Field::INT8: return load<std::int8_t>(p);
  case Field::UINT8: return load<std::uint8_t>(p);
  case Field::INT16: return load<std::int16_t>(p);
  case Field::UINT16: return load<std::uint16_t>(p);
  case Field::INT32: return load<std::int32_t>(p);
  case Field::UINT32: return load<std::uint32_t>(p);
  case Field::FLOAT32: return load<float>(p);
  default: return load<double>(p); // FLOAT64; checkFieldLayout let no other type through
  }
}

/// Writes `v` as T at `p`; false when T cannot hold it (out of range, a fraction for an integer).
template <typename T> bool store(double v, std::uint8_t* p) {
  if constexpr (std::is_floating_point_v<T>) {
    if (std::isfinite(v) && std::abs(v) > std::numeric_limits<T>::max())
      return false;
  } else {
    if (!(v >= static_cast<double>(std::numeric_limits<T>::lowest()) &&
          v <= static_cast<double>(std::numeric_limits<T>::max()) && v == std::floor(v)))
      return false;
  }
  const T t = static_cast<T>(v);
  std::memcpy(p, &t, sizeof t);
  return true;
}

bool writeValue(double v, std::uint8_t type, std::uint8_t* p) {
  switch (type) {
  case Field::INT8: return store<std::int8_t>(v, p);
  case Field::UINT8: return store<std::uint8_t>(v, p);
  case Field::INT16: return store<std::int16_t>(v, p);
  case Field::UINT16: return store<std::uint16_t>(v, p);
  case Field::INT32: return store<std::int32_t>(v, p);
  case Field::UINT32: return store<std::uint32_t>(v, p);
  case Field::FLOAT32: return store<float>(v, p);
  default: return store<double>(v, p);
  }
}

const char* typeName(std::uint8_t type) {
  static const char* kNames[] = {"?", "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return type <= Field::FLOAT64 ? kNames[type] : "?";
}

/// The fields with their new types, at offsets packed in their order.
std::vector<Field> convertedLayout(const std::vector<Field>& fields, const std::vector<std::uint8_t>& types,
                                   std::uint32_t& point_step) {
  std::vector<Field> out = fields;
  point_step = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].datatype = types[i];
    out[i].offset = point_step;
    point_step += std::max<std::uint32_t>(out[i].count, 1) * static_cast<std::uint32_t>(pcl::getFieldSize(types[i]));
  }
  return out;
}

} // namespace

void requireFields(const pcl::PCLPointCloud2& blob, const std::vector<Field>& wanted, const std::string& path) {
  const auto colour = [](const std::string& name) { return name == "rgb" || name == "rgba"; };
  for (const Field& field : wanted) {
    const bool found = std::any_of(blob.fields.begin(), blob.fields.end(), [&](const Field& f) {
      return f.name == field.name || (colour(f.name) && colour(field.name));
    });
    if (!found)
      throw IOError("cloud '" + path + "' has no field '" + field.name + "'");
  }
}

void convertFieldTypes(pcl::PCLPointCloud2& blob, const std::vector<Field>& wanted, const std::string& path) {
  std::vector<std::uint8_t> types;
  bool convert = false;
  for (Field& f : blob.fields) {
    const auto w = std::find_if(wanted.begin(), wanted.end(), [&](const Field& x) { return x.name == f.name; });
    types.push_back(f.datatype);
    if (w == wanted.end() || w->datatype == f.datatype)
      continue;
    if (f.name == "rgb" || f.name == "rgba") {
      if (pcl::getFieldSize(f.datatype) == pcl::getFieldSize(w->datatype))
        f.datatype = types.back() = w->datatype; // the same four bytes, read as the point type reads them
      continue;
    }
    types.back() = w->datatype;
    convert = true;
  }
  if (!convert)
    return;

  std::uint32_t step = 0;
  const std::vector<Field> fields = convertedLayout(blob.fields, types, step);
  const std::size_t points = static_cast<std::size_t>(blob.width) * blob.height;
  std::vector<std::uint8_t> data(points * step);
  for (std::size_t i = 0; i < points; ++i) {
    const std::uint8_t* from = blob.data.data() + i * blob.point_step;
    std::uint8_t* to = data.data() + i * step;
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const Field& a = blob.fields[k];
      const Field& b = fields[k];
      const std::size_t count = std::max<std::uint32_t>(a.count, 1), size_a = pcl::getFieldSize(a.datatype);
      if (a.datatype == b.datatype) {
        std::memcpy(to + b.offset, from + a.offset, count * size_a);
        continue;
      }
      for (std::size_t c = 0; c < count; ++c) {
        const double v = readValue(from + a.offset + c * size_a, a.datatype);
        if (!writeValue(v, b.datatype, to + b.offset + c * pcl::getFieldSize(b.datatype))) {
          std::ostringstream value;
          value << v;
          throw IOError("cloud '" + path + "': field '" + a.name + "' (" + typeName(a.datatype) + ") of point " +
                        std::to_string(i) + " is " + value.str() + ", which " + typeName(b.datatype) +
                        " cannot hold");
        }
      }
    }
  }
  blob.fields = fields;
  blob.point_step = step;
  blob.row_step = step * blob.width;
  blob.data = std::move(data);
}

} // namespace msf
