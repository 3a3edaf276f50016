// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/message_text.h>

#include <algorithm>
#include <cmath>

namespace msf::limits {

void checkThreads(int threads, const std::string& name) {
  if (threads < 0 || threads > kMaxThreads)
    throw ConfigError(name + " must be 0 (all cores) .. " + std::to_string(kMaxThreads) + ", not " +
                      std::to_string(threads));
}

void checkImageSize(long long width, long long height, const std::string& what) {
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide)
    throw InvalidInputError(what + ": image size " + std::to_string(width) + "x" + std::to_string(height) +
                            " is outside 1x1 .. " + std::to_string(kMaxImageSide) + "x" +
                            std::to_string(kMaxImageSide));
  if (width * height > kMaxImagePixels)
    throw InvalidInputError(what + ": image size " + std::to_string(width) + "x" + std::to_string(height) + " has " +
                            std::to_string(width * height) + " pixels, more than the " +
                            std::to_string(kMaxImagePixels) + " (4096x4096) a frame may have: each of its stages "
                            "would take gigabytes and minutes");
}

void checkRigid(const Eigen::Isometry3d& T, const std::string& what) {
  const Eigen::Matrix4d& M = T.matrix();
  if (!M.allFinite())
    throw InvalidInputError(what + " has a value that is not finite (NaN or inf)");
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 0)
    throw InvalidInputError(what + " is not a rigid transform: its last row is not 0 0 0 1");
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  const double orthonormality = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = R.determinant();
  if (orthonormality > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance)
    throw InvalidInputError(what + " is not a rigid transform: its rotation is not orthonormal (|R^T R - I| = " +
                            number(orthonormality) + ", det R = " + number(det) + ", tolerance " +
                            number(kRotationTolerance) + ")");
  const double t = M.topRightCorner<3, 1>().cwiseAbs().maxCoeff();
  if (t > kMaxTranslationM)
    throw InvalidInputError(what + " has a translation of " + number(t) + " m, beyond " + number(kMaxTranslationM) + " m");
}

std::int64_t checkedRound(double value, std::int64_t lo, std::int64_t hi, const std::string& what) {
  if (!std::isfinite(value) || value < static_cast<double>(lo) - 0.5 || value > static_cast<double>(hi) + 0.5)
    throw InvalidInputError(what + " " + number(value) + " is outside " + std::to_string(lo) + " .. " +
                            std::to_string(hi));
  return std::clamp<std::int64_t>(std::llround(value), lo, hi);
}

} // namespace msf::limits
