// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <memory>
#include <vector>

namespace msf {

/// The open sky of one camera image (evaluation protocol 6): the pixels where the camera looked
/// past every surface. Found from the image and the LiDAR alone, so it needs no ground truth:
///  1. sky-like pixels: bright (grey at least the minimum brightness, an overexposed sky
///     included), blank (the grey's standard deviation over 5x5 pixels at most the maximum
///     texture: leaves, branches, poles and edges have more) and, when the image has colour,
///     grey-white or blue (HSV saturation at most the maximum, or a hue between cyan and
///     violet: a red roof or green leaves are neither);
///  2. above the LiDAR: a pixel lies above the highest return projected into any column
///     within the column window of its own (a wall, a roof or a tree returns; the sky does not,
///     and the scan's columns are sparser than the image's);
///  3. connected to the image's top edge (8-neighbours; a white wall or a car below a
///     surface is not sky);
///  4. eroded by the border, so that a surface's outline blurred by the image or by the voxels
///     of a map does not count as covering the sky.
/// The steps are OpenCV's (cvtColor, boxFilter, inRange, connectedComponents, erode).
/// Within the mask, clearSky() picks what only the sky looks like: a blank wall may be as
/// grey-white as an overcast sky, but it is rarely clipped or blue.
class SkyMask {
public:
  using Ptr = std::shared_ptr<SkyMask>;

  /// Grey level (0-255) a sky pixel has at least.
  void setMinBrightness(double grey) { min_brightness_ = grey; }
  double getMinBrightness() const { return min_brightness_; }
  /// Standard deviation of the grey over 5x5 pixels a sky pixel has at most.
  void setMaxTexture(double grey) { max_texture_ = grey; }
  double getMaxTexture() const { return max_texture_; }
  /// HSV saturation (0-255) a grey-white sky pixel has at most (a blue one may have more).
  void setMaxSaturation(double saturation) { max_saturation_ = saturation; }
  double getMaxSaturation() const { return max_saturation_; }
  /// Columns on each side whose highest LiDAR return also bounds a pixel's column.
  void setColumnWindow(int columns) { column_window_ = columns; }
  int getColumnWindow() const { return column_window_; }
  /// Level (0-255) at which a channel counts as clipped (clearSky): overexposed.
  void setClippedLevel(double level) { clipped_level_ = level; }
  double getClippedLevel() const { return clipped_level_; }
  /// Pixels taken off the mask's outline.
  void setBorder(int pixels) { border_ = pixels; }
  int getBorder() const { return border_; }

  /// The mask (CV_8UC1, 255 = open sky) of `image` (CV_8UC1 grey or CV_8UC3 BGR) given the
  /// LiDAR's returns projected into the same camera (`returns`: CV_32FC1 of the image's size,
  /// > 0 where a return lands). Throws InvalidInputError for another type or size, or
  /// ConfigError for a setting out of range (a negative window or border).
  cv::Mat compute(const cv::Mat& image, const cv::Mat& returns) const;
  /// Steps 1-3 alone: the open sky up to where the image's texture starts, its outline kept
  /// (takeBorder then gives compute's mask). Throws as compute does.
  cv::Mat computeWithoutBorder(const cv::Mat& image, const cv::Mat& returns) const;

  /// Takes the border off `mask` (CV_8UC1, 255 = sky) in place, as compute's step 4 does: a
  /// surface's outline blurred by the image or by a map's voxels is not counted as sky.
  void takeBorder(cv::Mat& mask) const;

  /// The pixels of `sky` (a mask of `image` as compute finds it, CV_8UC1) whose colour only the sky has: a
  /// channel clipped (at least the clipped level) or, in colour, blue with more saturation
  /// than a grey-white pixel (the maximum saturation) has. CV_8UC1, 255 = clear sky. Throws
  /// InvalidInputError for an image or mask of another type or size.
  cv::Mat clearSky(const cv::Mat& image, const cv::Mat& sky) const;

  /// The clipped pixels along the outline of `sky` (a mask of `image` as computeWithoutBorder
  /// finds it, CV_8UC1) that the texture keeps out of it: those reached from the mask within the
  /// border through pixels with a channel clipped, above the LiDAR's highest returns (step 2).
  /// A clipped pixel has no texture of its own; its window sees the edge of the surface beside
  /// it. CV_8UC1, 255 = reached. Throws as compute does.
  cv::Mat clippedOutline(const cv::Mat& image, const cv::Mat& returns, const cv::Mat& sky) const;

  /// Per image column, the depth of the nearest return on the highest ring within its column
  /// window (the returns within 3 rows of the highest, the one that bounds step 2), 0 where the
  /// window has none. A blank wall that the mask takes for sky continues above its highest
  /// returns at their depth (a vertical plane keeps one depth down an image column), so what
  /// lies nearer than this depth is in front of any such wall.
  /// Throws InvalidInputError for `returns` not CV_32FC1.
  std::vector<float> topReturnDepth(const cv::Mat& returns) const;

  /// Per image column, the depth a blank wall covering it would have: on each side of the column
  /// within its window (the column itself on both), the nearest return on that side's highest
  /// ring, and of the two sides the farther (a side with none: the other's; 0 where the window
  /// has none). A wall goes on past a pixel on both sides; a pole or a crown's edge beside it lies
  /// on one side only, and does not stand for the sky beyond it. Throws as topReturnDepth does.
  std::vector<float> wallDepth(const cv::Mat& returns) const;

private:
  /// A column's highest return, or the nearest on the highest ring within its window: its row
  /// (the image's height: none) and depth.
  struct TopReturn {
    int row;
    float depth;
  };
  /// Each column's own highest return. Throws InvalidInputError for `returns` not CV_32FC1.
  static std::vector<TopReturn> highestReturns(const cv::Mat& returns);
  std::vector<TopReturn> topReturns(const cv::Mat& returns) const;
  /// Step 1: bright, blank and sky-coloured pixels (255).
  cv::Mat skyLike(const cv::Mat& image) const;
  /// Step 3: keeps the components of `sky` (CV_8UC1) that touch its top row.
  static void keepOpenToTheTop(cv::Mat& sky);

  double min_brightness_ = 110.0;
  double max_texture_ = 6.0;
  double max_saturation_ = 70.0;
  double clipped_level_ = 250.0;
  int column_window_ = 8;
  int border_ = 3;
};

/// The open sky as the fused cloud carries it (PointXYZRGBWeight::sky_depth) and
/// TsdfIntegrator::carveSky takes it: CV_32FC1 of the mask's size, NaN where the pixel is not open
/// sky (`sky`, CV_8UC1, non-zero = sky), else the depth that bounds its ray, the depth of its
/// column's highest LiDAR return (`column_depth`, topReturnDepth); +inf where nothing does: in the
/// clear sky (`clear_sky`, CV_8UC1 of the mask's size, non-zero; or empty: none; SkyMask::clearSky)
/// and where the column has no return (0). Throws InvalidInputError for a mask of another type,
/// a clear sky of another type or size, or column depths not one per column.
cv::Mat skyDepthImage(const cv::Mat& sky, const std::vector<float>& column_depth, const cv::Mat& clear_sky = {});

} // namespace msf
