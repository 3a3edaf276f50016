// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/kitti_rig.h>

namespace msf::synthetic {

Calibration kittiRig() {
  Calibration c;
  c.source = "synthetic KITTI rig (2011_09_26 calibration)";
  const double f = 7.215377e+02, cx = 6.095593e+02, cy = 1.728540e+02;
  // Last columns of P_rect_00..03: the offsets of the four rectified cameras.
  const double offsets[4][3] = {{0.0, 0.0, 0.0},
                                {-3.875744e+02, 0.0, 0.0},
                                {4.485728e+01, 2.163791e-01, 2.745884e-03},
                                {-3.395242e+02, 2.199936e+00, 2.729905e-03}};
  for (int i = 0; i < 4; ++i) {
    c.P[i] << f, 0.0, cx, offsets[i][0], 0.0, f, cy, offsets[i][1], 0.0, 0.0, 1.0, offsets[i][2];
  }
  c.image_size = cv::Size(1242, 375);

  Eigen::Matrix3d R_rect;
  R_rect << 9.999239e-01, 9.837760e-03, -7.445048e-03, -9.869795e-03, 9.999421e-01, -4.278459e-03, 7.402527e-03,
      4.351614e-03, 9.999631e-01;
  Eigen::Matrix3d R_cam_velo;
  R_cam_velo << 7.533745e-03, -9.999714e-01, -6.166020e-04, 1.480249e-02, 7.280733e-04, -9.998902e-01,
      9.998621e-01, 7.523790e-03, 1.480755e-02;
  const Eigen::Vector3d t_cam_velo(-4.069766e-03, -7.631618e-02, -2.717806e-01);
  Eigen::Isometry3d T_cam_velo = Eigen::Isometry3d::Identity();
  // Re-orthonormalize: the file's 7-digit rotation is not exactly a rotation.
  T_cam_velo.linear() = Eigen::Quaterniond(R_cam_velo).normalized().toRotationMatrix();
  T_cam_velo.translation() = t_cam_velo;
  Eigen::Isometry3d T_rect = Eigen::Isometry3d::Identity();
  T_rect.linear() = Eigen::Quaterniond(R_rect).normalized().toRotationMatrix();
  c.T_cam0_velo = T_rect * T_cam_velo;
  return c;
}

} // namespace msf::synthetic
