#include "stages/ground/scan_processor.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::ground {

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

GroundFrame MakeGroundFrame(const proto::Rig& rig, const proto::GroundFrameParams& params) {
  GroundFrame frame;
  const Eigen::Matrix3d c_bl = ToEigen(rig.imu_from_lidar().rotation()).toRotationMatrix();
  Eigen::Vector3d up_l = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d g_f = ToEigen(rig.gravity_flat_in_imu());
  if (params.use_rig_up_direction() && g_f.norm() > 1e-6) {
    up_l = c_bl.transpose() * (-g_f.normalized());
    frame.s_from_lidar =
        Eigen::Quaterniond::FromTwoVectors(up_l, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
  if (params.sensor_height_guess_m() > 0.0) {
    frame.height_prior_m = params.sensor_height_guess_m();
  } else if (rig.imu_height_m() > 0.0 &&
             !(rig.has_starting_extrinsic() && !rig.starting_extrinsic().translation_known())) {
    // d_l = d_b + n_l · (C_bl^T r_b^{lb}) (the distance residual
    // e_dist = d_l − d_b − n_l^T C_bl^T r_b^{lb} = 0; docs/design.md §8) with n_l ≈ up.
    const Eigen::Vector3d r = ToEigen(rig.imu_from_lidar().translation());
    const double h = rig.imu_height_m() + up_l.dot(c_bl.transpose() * r);
    frame.height_prior_m = h > 0.0 && std::isfinite(h) ? h : 0.0;
  }
  return frame;
}

void PackMask(const uint8_t* binned_flag, const uint32_t* binned_source, size_t num_binned,
              size_t num_points, google::protobuf::RepeatedField<uint64_t>* mask) {
  mask->Resize(static_cast<int>((num_points + 63) / 64), 0);
  uint64_t* words = mask->mutable_data();
  for (size_t i = 0; i < num_binned; ++i) {
    if (!binned_flag[i]) continue;
    const uint32_t src = binned_source[i];
    words[src >> 6] |= uint64_t{1} << (src & 63u);
  }
}

ScanProcessor::ScanProcessor(const proto::GroundParams& params, const GroundFrame& frame,
                             Deskewer* deskewer)
    : frame_(frame),
      level_(!frame.s_from_lidar.isIdentity(1e-12)),
      deskewer_(params.deskew().enabled() ? deskewer : nullptr),
      require_imu_coverage_(params.deskew().require_imu_coverage()),
      store_point_masks_(params.store_point_masks()),
      segmenter_(params.zone_model(), params.region_fit()),
      fitter_(params.plane_fit(), params.gates(), params.covariance_floor()) {}

proto::GroundPlane ScanProcessor::Process(proto::Scan* scan) {
  const auto t0 = Clock::now();
  proto::GroundPlane out;
  out.set_stamp_ns(scan->stamp_ns());
  out.set_scan_index(scan->index());
  const size_t n = static_cast<size_t>(scan->x_size());
  out.set_num_points(static_cast<uint32_t>(n));
  out.set_height_prior_m(frame_.height_prior_m);
  deskew_s_ = segment_s_ = fit_s_ = 0.0;
  if (!Deskew(scan, &out)) {
    deskew_s_ = Seconds(t0, Clock::now());
    return out;
  }
  const auto t1 = Clock::now();
  deskew_s_ = Seconds(t0, t1);

  const float *x, *y, *z;
  ToSegmentationFrame(*scan, &x, &y, &z);
  const SegmentationSummary seg = segmenter_.Segment(x, y, z, n, frame_.height_prior_m);
  const auto t2 = Clock::now();
  segment_s_ = Seconds(t1, t2);
  out.set_num_ground_points(seg.num_ground);
  if (seg.has_reference) out.set_ground_reference_z_m(seg.reference_z_m);

  const ScanPlane plane = fitter_.Fit(segmenter_, seg, frame_.height_prior_m, &inlier_);
  fit_s_ = Seconds(t2, Clock::now());
  out.set_num_inliers(plane.num_inliers);
  out.set_fit_radius_m(plane.fit_radius_m);
  out.set_azimuth_coverage(plane.coverage);
  out.set_radial_spread_ratio(plane.radial_spread);
  out.set_reject_reason(plane.reason);
  out.set_reject_detail(plane.detail);
  if (plane.has_plane()) SetPlaneInLidar(plane, &out);
  out.set_valid(out.reject_reason() == proto::GROUND_OK);
  if (store_point_masks_) {
    PackMask(segmenter_.binned_ground(), segmenter_.binned_source(), segmenter_.num_binned(), n,
             out.mutable_ground_mask());
    PackMask(inlier_.data(), segmenter_.binned_source(), segmenter_.num_binned(), n,
             out.mutable_inlier_mask());
  }
  return out;
}

bool ScanProcessor::Deskew(proto::Scan* scan, proto::GroundPlane* out) {
  bool deskewed = scan->deskewed();
  if (!deskewed && deskewer_ != nullptr && scan->x_size() > 0 &&
      scan->time_offset_ns_size() == scan->x_size()) {
    deskewed = deskewer_->Deskew(scan->stamp_ns(), scan->time_offset_ns().data(),
                                 static_cast<size_t>(scan->x_size()),
                                 scan->mutable_x()->mutable_data(),
                                 scan->mutable_y()->mutable_data(),
                                 scan->mutable_z()->mutable_data());
    if (!deskewed && require_imu_coverage_) {
      out->set_valid(false);
      out->set_reject_reason(proto::GROUND_NO_IMU_COVERAGE);
      out->set_reject_detail("IMU samples do not cover the sweep (with time_offset_s)");
      return false;
    }
    scan->set_deskewed(deskewed);
  }
  out->set_deskewed(deskewed);
  return true;
}

void ScanProcessor::ToSegmentationFrame(const proto::Scan& scan, const float** x,
                                        const float** y, const float** z) {
  *x = scan.x().data();
  *y = scan.y().data();
  *z = scan.z().data();
  if (!level_) return;
  const size_t n = static_cast<size_t>(scan.x_size());
  const Eigen::Matrix3f r = frame_.s_from_lidar.cast<float>();
  sx_.resize(n);
  sy_.resize(n);
  sz_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f p = r * Eigen::Vector3f((*x)[i], (*y)[i], (*z)[i]);
    sx_[i] = p.x();
    sy_[i] = p.y();
    sz_[i] = p.z();
  }
  *x = sx_.data();
  *y = sy_.data();
  *z = sz_.data();
}

// n_l = C_sl^T n_s, c_l = C_sl^T c_s, d unchanged; the covariance of (n, d)
// rotated likewise. A non-finite result is a GROUND_FIT_FAILED rejection.
void ScanProcessor::SetPlaneInLidar(const ScanPlane& plane, proto::GroundPlane* out) const {
  const Eigen::Matrix3d c_ls = frame_.s_from_lidar.transpose();
  const Eigen::Vector3d n_l = c_ls * plane.fit.normal;
  const Eigen::Vector3d c_l = c_ls * plane.fit.centroid;
  Eigen::Matrix4d rot = Eigen::Matrix4d::Identity();
  rot.topLeftCorner<3, 3>() = c_ls;
  const Eigen::Matrix4d cov = rot * plane.covariance * rot.transpose();
  const bool finite = n_l.allFinite() && c_l.allFinite() && cov.allFinite() &&
                      std::isfinite(plane.fit.offset) && std::isfinite(plane.rms_m) &&
                      plane.fit.eigenvalues.allFinite();
  if (!finite) {
    if (plane.reason == proto::GROUND_OK) {
      out->set_reject_reason(proto::GROUND_FIT_FAILED);
      out->set_reject_detail("non-finite plane");
    }
    return;
  }
  *out->mutable_normal_in_lidar() = ToProto(n_l);
  *out->mutable_centroid_in_lidar() = ToProto(c_l);
  out->set_height_m(plane.fit.offset);
  out->set_rms_m(plane.rms_m);
  out->set_tilt_deg(geometry::RadToDeg(std::acos(std::clamp(n_l.z(), -1.0, 1.0))));
  out->set_eigenvalue_min(plane.fit.eigenvalues(0));
  out->set_eigenvalue_mid(plane.fit.eigenvalues(1));
  out->set_eigenvalue_max(plane.fit.eigenvalues(2));
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out->add_covariance(cov(r, c));
  }
  const double normal_var = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                cov.topLeftCorner<3, 3>(), Eigen::EigenvaluesOnly)
                                .eigenvalues()
                                .maxCoeff();
  out->set_normal_std_deg(geometry::RadToDeg(std::sqrt(std::max(0.0, normal_var))));
  out->set_height_std_m(std::sqrt(std::max(0.0, cov(3, 3))));
}

}  // namespace tiltcal::ground
