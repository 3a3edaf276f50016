// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <Eigen/Geometry>

#include <cstdint>
#include <string>

/// Limits a hostile or mistaken input is checked against before anything is allocated or
/// converted: a run that cannot be done in reasonable memory or time, or whose numbers are
/// not physical, stops with an error naming the option, key or file instead of crashing,
/// running away or writing a silently wrong result.
namespace msf::limits {

/// Threads a `threads` option may ask for (0 = all the cores).
inline constexpr int kMaxThreads = 256;
/// Side of an image, canvas or calibration in pixels: KITTI's is 1242, 8192 leaves room for
/// any camera of the field and keeps every pixel index, area and offset within an int.
inline constexpr int kMaxImageSide = 8192;
/// Pixels of an image: 2^24 (4096x4096, twice the largest automotive camera's). A pixel takes
/// tens of bytes in each stage of a frame (an organized cloud alone 32, the matcher's costs,
/// the writer's buffers): a larger frame needs gigabytes and minutes, not the fraction of a
/// second a frame is meant to take.
inline constexpr long long kMaxImagePixels = 1LL << 24;
/// Points one LiDAR scan file may hold: the densest sensors give about half a million a sweep;
/// 2^24 (256 MB of KITTI records) leaves room for any, and a larger file is not one scan (a
/// 2 GB file was read whole before anything looked at it).
inline constexpr std::uint64_t kMaxScanPoints = std::uint64_t{1} << 24;
/// Largest magnitude of a translation in metres (a pose, a calibration's extrinsics):
/// 1000 km, beyond any drive; divided by the smallest voxel (1 mm) it still fits an int.
inline constexpr double kMaxTranslationM = 1e6;
/// Largest depth in metres an input depth image or cloud may hold: KITTI's LiDAR reaches
/// 120 m; a depth of 1e30 m is a broken input, not a far surface.
inline constexpr double kMaxDepthM = 1000.0;
/// Plausible length of a stereo pair's baseline in metres: below a millimetre a pair sees no
/// depth beyond arm's length, and no rig is 10 m wide (its cameras would share little view);
/// KITTI's 0.54 m written in millimetres or kilometres lands outside, as does a zero.
inline constexpr double kMinBaselineM = 1e-3;
inline constexpr double kMaxBaselineM = 10.0;
/// How far the intrinsics (fx, fy, cx, cy) of the two cameras of a rectified pair may differ
/// in pixels: rectification gives both the same, up to the digits a file keeps.
inline constexpr double kRectifiedIntrinsicsTolerancePx = 0.01;
/// Tolerance of |R^T R - I| (largest element) and of |det R - 1| for a rotation that was
/// written with 9 to 12 digits (KITTI's poses and calibrations).
inline constexpr double kRotationTolerance = 1e-3;

/// Throws ConfigError naming `name` unless 0 <= threads <= kMaxThreads.
void checkThreads(int threads, const std::string& name);

/// Throws InvalidInputError naming `what` unless 1 <= width, height <= kMaxImageSide and
/// width x height <= kMaxImagePixels.
void checkImageSize(long long width, long long height, const std::string& what);

/// Throws InvalidInputError naming `what` unless T's linear part is a rotation (orthonormal
/// within kRotationTolerance, determinant +1), its translation finite and within
/// kMaxTranslationM, and its last row 0 0 0 1.
void checkRigid(const Eigen::Isometry3d& T, const std::string& what);

/// `value` rounded to the nearest integer when it is finite and within [lo, hi]; throws
/// InvalidInputError naming `what` otherwise (a double -> int cast of 1e30 is undefined).
std::int64_t checkedRound(double value, std::int64_t lo, std::int64_t hi, const std::string& what);

} // namespace msf::limits
