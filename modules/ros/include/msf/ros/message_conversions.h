// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/calibration.h>
#include <msf/io/frame_source.h>
#include <msf/reconstruction/marching_cubes.h>

#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/Marker.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <string>

/// ROS 1 messages to the library's types and back: what the bag reader, the bag writer and the
/// node convert, in one place, so the three read a message alike.
namespace msf {

/// Nanoseconds since the epoch of a message stamp, and back.
std::int64_t stampNs(const ros::Time& stamp);
ros::Time stampFromNs(std::int64_t ns);

/// A LiDAR's PointCloud2 (float32 x y z, and `intensity` or kitti2bag's older `i`; optionally
/// `ring`, an 8- or 16-bit unsigned beam id, and `time`, float32 or float64 seconds within the
/// sweep) into frame.scan (the points in the sensor's frame, in the order sent), and
/// frame.point_ring and frame.point_time_s when the fields are there (times from the sweep's
/// start: a driver that stamps the sweep's end sends negative offsets). Non-finite points are
/// dropped, as loadVelodyneBin does. x, y and z may be float32, float64 or integers. Throws
/// InvalidInputError naming `what` and the field when x, y or z is missing or a field does not
/// fit in a point.
void scanFromMessage(const sensor_msgs::PointCloud2& message, Frame& frame, const std::string& what);

/// Whether a scan read by scanFromMessage has one time at every point (a `time` field of one
/// value): a LiDAR that takes each scan at once, or a driver that leaves the field unset, which
/// only the rig can tell apart. False for a scan without times.
bool scanTimesAreOneInstant(const Frame& frame);
/// frame.scan as a PointCloud2 of float32 x y z intensity (kitti2bag's fields), with `ring`
/// (uint16) and `time` (float32) when the frame has them.
sensor_msgs::PointCloud2 scanToMessage(const Frame& frame, const std_msgs::Header& header);

/// A stereo pair's Images as grey (CV_8UC1), converted by cv_bridge from the encodings it knows
/// (mono8, mono16, bgr8, rgb8, ...); 16-bit ones scaled to 8 bits by the bits the brighter image
/// needs (significantBits), one gain for both, so that a 10- or 12-bit camera is not dark.
/// Throws InvalidInputError naming `what_left` or `what_right` for an encoding it cannot read.
void greyPairFromMessages(const sensor_msgs::Image& left, const sensor_msgs::Image& right, cv::Mat& left_grey,
                          cv::Mat& right_grey, const std::string& what_left, const std::string& what_right);
/// An Image as BGR (CV_8UC3), a 16-bit one scaled by the bits it needs. Throws as above.
cv::Mat colorFromMessage(const sensor_msgs::Image& message, const std::string& what);
/// A grey (mono8), BGR (bgr8) or float (32FC1) image as a message.
sensor_msgs::Image imageToMessage(const cv::Mat& image, const std_msgs::Header& header);

/// A rectified camera's projection: CameraInfo's P, which maps points of the reference (left)
/// camera's rectified frame to pixels (KITTI's convention, and ROS's for a stereo pair).
/// Throws InvalidInputError naming `what` when P is all zero (a camera never calibrated).
Calibration::Projection projectionFromCameraInfo(const sensor_msgs::CameraInfo& info, const std::string& what);
/// Camera `camera` of a calibration as CameraInfo: its P, K (P's left 3x3), R = identity, no
/// distortion (the images are rectified), the calibration's image size.
sensor_msgs::CameraInfo cameraInfoFromCalibration(const Calibration& calibration, int camera,
                                                  const std_msgs::Header& header);

/// The rig of a rectified stereo pair from its CameraInfo (and a colour camera's, or none: then
/// camera 2 is the left one) and the LiDAR-to-left-camera extrinsic, validated; `source` names
/// it in messages. Camera 3 (the colour pair's right camera, which the stages do not use) is
/// camera 2 moved by the grey pair's baseline. Throws CalibrationError for a P that is not a
/// rectified camera's, InvalidInputError for an uncalibrated one.
Calibration rigFromCameraInfo(const sensor_msgs::CameraInfo& left, const sensor_msgs::CameraInfo& right,
                              const sensor_msgs::CameraInfo* color, const Eigen::Isometry3d& T_cam0_velo,
                              cv::Size image_size, const std::string& source);

/// Frame `index`'s time from the scan stamps, as every reader gives it: frame.timestamp in
/// seconds from `first_scan_ns` (exact nanoseconds, then one correctly rounded division: the
/// seconds a KITTI times.txt holds), and the scan's header (its sensor frame, microseconds
/// from the first frame, seq = index).
void stampFrame(Frame& frame, std::size_t index, std::int64_t scan_ns, std::int64_t first_scan_ns,
                const std::string& lidar_frame);

Eigen::Isometry3d isometryFromTransform(const geometry_msgs::Transform& transform);
geometry_msgs::Transform transformFromIsometry(const Eigen::Isometry3d& T);

/// A mesh as an RViz triangle list: three points per triangle, each with its vertex's colour.
visualization_msgs::Marker meshToMarker(const TriangleMesh& mesh, const std_msgs::Header& header);

} // namespace msf
