// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <pcl/PCLPointCloud2.h>
#include <pcl/PCLPointField.h>

#include <string>
#include <vector>

namespace msf {

/// Gives the fields of `blob` that `wanted` names (a point type's, pcl::detail::FieldAdder)
/// the wanted numeric type, value by value: x, y, z written as int32 or float64 become the
/// float32 a PCL point holds. pcl::fromPCLPointCloud2 reads a field of another type as zeros
/// with a warning only. A value the wanted type cannot hold (a float64 beyond float32's range,
/// a fraction or a negative for an integer field) throws IOError naming `path`, the field, the
/// point and the value. rgb and rgba keep their bits (a packed colour, 4 bytes of any type).
/// Fields of the same type, and fields not wanted, are left as they are.
void convertFieldTypes(pcl::PCLPointCloud2& blob, const std::vector<pcl::PCLPointField>& wanted,
                       const std::string& path);

/// Throws IOError "cloud 'PATH' has no field 'NAME'" for the first field `wanted` names that
/// `blob` lacks (PCL's rgb and rgba stand for each other): PCL itself only warns and fills zeros.
void requireFields(const pcl::PCLPointCloud2& blob, const std::vector<pcl::PCLPointField>& wanted,
                   const std::string& path);

} // namespace msf
