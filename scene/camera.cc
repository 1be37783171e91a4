#include "scene/camera.h"

#include <cmath>
#include <limits>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace daylit::scene {
namespace {

cv::Matx33d ToCv(const glm::dmat3& m) {
  cv::Matx33d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = m[c][r];
  }
  return out;
}

glm::dmat3 FromCv(const cv::Matx33d& m) {
  glm::dmat3 out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[c][r] = m(r, c);
  }
  return out;
}

cv::Matx33d CameraMatrix(const CameraIntrinsics& k) {
  return {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
}

cv::Mat Distortion(const CameraIntrinsics& k) {
  if (k.distortion.empty()) return cv::Mat();
  return cv::Mat(k.distortion, true).reshape(1, 1);
}

}  // namespace

bool CameraIntrinsics::HasDistortion() const {
  for (const double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

double OrthonormalityError(const glm::dmat3& r) {
  const glm::dmat3 e = glm::transpose(r) * r - glm::dmat3(1.0);
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(e[c][k]));
  }
  return worst;
}

bool IsRotation(const glm::dmat3& r, double tolerance) {
  return OrthonormalityError(r) <= tolerance && glm::determinant(r) > 0.0;
}

glm::dmat3 NearestRotation(const glm::dmat3& r) {
  cv::SVD svd(cv::Mat(ToCv(r)), cv::SVD::FULL_UV);
  cv::Mat nearest = svd.u * svd.vt;
  if (cv::determinant(nearest) < 0.0) {
    cv::Mat d = cv::Mat::eye(3, 3, CV_64F);
    d.at<double>(2, 2) = -1.0;
    nearest = svd.u * d * svd.vt;
  }
  return FromCv(cv::Matx33d(nearest));
}

CameraModel::CameraModel(const CameraIntrinsics& intrinsics, const RigidPose& cam_from_world)
    : intrinsics_(intrinsics), cam_from_world_(cam_from_world) {}

std::vector<glm::dvec2> CameraModel::Project(const std::vector<glm::dvec3>& points_in_world) const {
  std::vector<glm::dvec2> out(points_in_world.size());
  if (points_in_world.empty()) return out;
  std::vector<cv::Point3d> object;
  object.reserve(points_in_world.size());
  for (const glm::dvec3& p : points_in_world) object.emplace_back(p.x, p.y, p.z);
  cv::Vec3d rvec;
  cv::Rodrigues(ToCv(cam_from_world_.rotation), rvec);
  const cv::Vec3d tvec(cam_from_world_.translation.x, cam_from_world_.translation.y,
                       cam_from_world_.translation.z);
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, rvec, tvec, CameraMatrix(intrinsics_), Distortion(intrinsics_), image);
  for (size_t i = 0; i < out.size(); ++i) {
    const glm::dvec3 in_cam = cam_from_world_.rotation * points_in_world[i] + cam_from_world_.translation;
    out[i] = in_cam.z > 0.0 ? glm::dvec2(image[i].x, image[i].y)
                            : glm::dvec2(std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

glm::dvec2 CameraModel::Project(const glm::dvec3& point_in_world) const {
  return Project(std::vector<glm::dvec3>{point_in_world}).front();
}

std::vector<glm::dvec3> CameraModel::UnprojectToWorldRays(const std::vector<glm::dvec2>& pixels) const {
  std::vector<glm::dvec3> out(pixels.size());
  if (pixels.empty()) return out;
  std::vector<cv::Point2d> distorted;
  distorted.reserve(pixels.size());
  for (const glm::dvec2& p : pixels) distorted.emplace_back(p.x, p.y);
  std::vector<cv::Point2d> normalized;
  // Iterates until the residual is below 1e-10 of the normalised coordinates, not a fixed 5
  // steps: strong distortion at the image corners needs more.
  cv::undistortPoints(distorted, normalized, CameraMatrix(intrinsics_), Distortion(intrinsics_),
                      cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  const glm::dmat3 world_from_cam = glm::transpose(cam_from_world_.rotation);
  for (size_t i = 0; i < out.size(); ++i) {
    out[i] = glm::normalize(world_from_cam * glm::dvec3(normalized[i].x, normalized[i].y, 1.0));
  }
  return out;
}

glm::dvec3 CameraModel::UnprojectToWorldRay(const glm::dvec2& pixel) const {
  return UnprojectToWorldRays(std::vector<glm::dvec2>{pixel}).front();
}

bool SolvePoseFromCorrespondences(const CameraIntrinsics& intrinsics,
                                  const std::vector<glm::dvec3>& points_in_world,
                                  const std::vector<glm::dvec2>& pixels, PoseFit* fit,
                                  std::string* why) {
  if (points_in_world.size() != pixels.size() || points_in_world.size() < 4) {
    *why = "at least 4 correspondences are needed, got " + std::to_string(points_in_world.size());
    return false;
  }
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < pixels.size(); ++i) {
    object.emplace_back(points_in_world[i].x, points_in_world[i].y, points_in_world[i].z);
    image.emplace_back(pixels[i].x, pixels[i].y);
  }
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(object, image, CameraMatrix(intrinsics), Distortion(intrinsics), rvec, tvec,
                      false, cv::SOLVEPNP_SQPNP)) {
      *why = "no pose fits the correspondences (degenerate points?)";
      return false;
    }
    cv::solvePnPRefineLM(object, image, CameraMatrix(intrinsics), Distortion(intrinsics), rvec, tvec);
  } catch (const cv::Exception& e) {
    *why = std::string("OpenCV could not solve the pose: ") + e.err;
    return false;
  }
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  fit->cam_from_world.rotation = FromCv(r);
  fit->cam_from_world.translation = {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
  fit->count = static_cast<int>(pixels.size());
  const CameraModel camera(intrinsics, fit->cam_from_world);
  const std::vector<glm::dvec2> reprojected = camera.Project(points_in_world);
  double sum_sq = 0.0;
  fit->max_reprojection_px = 0.0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const double e = glm::length(reprojected[i] - pixels[i]);
    if (!std::isfinite(e)) {
      *why = "the solved pose puts correspondence " + std::to_string(i) + " behind the camera";
      return false;
    }
    sum_sq += e * e;
    fit->max_reprojection_px = std::max(fit->max_reprojection_px, e);
  }
  fit->rms_reprojection_px = std::sqrt(sum_sq / static_cast<double>(pixels.size()));
  return true;
}

}  // namespace daylit::scene
