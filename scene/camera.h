// The calibrated camera: OpenCV pinhole + distortion (k1, k2, p1, p2[, k3 ...]) and the pose
// cam_from_world (x right, y down, z forward). Projection and unprojection go through OpenCV.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace daylit::scene {

struct CameraIntrinsics {
  int width = 0;   // pixels
  int height = 0;  // pixels
  double fx = 0.0, fy = 0.0;  // focal lengths, pixels
  double cx = 0.0, cy = 0.0;  // principal point, pixels (pixel centres at integers)
  std::vector<double> distortion;  // OpenCV order; 0, 4, 5, 8, 12 or 14 coefficients

  bool HasDistortion() const;
};

// cam_from_world: x_in_cam = rotation * x_in_world + translation.
struct RigidPose {
  glm::dmat3 rotation{1.0};
  glm::dvec3 translation{0.0};

  glm::dvec3 CenterInWorld() const { return -glm::transpose(rotation) * translation; }
};

// Largest |RᵀR − I| entry; and whether `r` is a proper rotation to `tolerance`.
double OrthonormalityError(const glm::dmat3& r);
bool IsRotation(const glm::dmat3& r, double tolerance);
// The nearest proper rotation (SVD), to remove rounding in hand-typed matrices.
glm::dmat3 NearestRotation(const glm::dmat3& r);

class CameraModel {
 public:
  CameraModel(const CameraIntrinsics& intrinsics, const RigidPose& cam_from_world);

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  const RigidPose& cam_from_world() const { return cam_from_world_; }
  glm::dvec3 CenterInWorld() const { return cam_from_world_.CenterInWorld(); }

  // Pixel positions of world points, distortion applied. Points behind the camera get NaN.
  std::vector<glm::dvec2> Project(const std::vector<glm::dvec3>& points_in_world) const;
  glm::dvec2 Project(const glm::dvec3& point_in_world) const;

  // Unit world-space ray directions through pixels (distortion removed iteratively by OpenCV).
  std::vector<glm::dvec3> UnprojectToWorldRays(const std::vector<glm::dvec2>& pixels) const;
  glm::dvec3 UnprojectToWorldRay(const glm::dvec2& pixel) const;

 private:
  CameraIntrinsics intrinsics_;
  RigidPose cam_from_world_;
};

struct PoseFit {
  RigidPose cam_from_world;
  double rms_reprojection_px = 0.0;
  double max_reprojection_px = 0.0;
  int count = 0;
};

// Camera pose from ≥ 4 world<->pixel correspondences: OpenCV SQPnP for a global solution, then
// Levenberg-Marquardt refinement (solvePnPRefineLM) of the reprojection error. Returns false and
// sets `why` when there are too few points, they are degenerate, or the solution puts points
// behind the camera.
bool SolvePoseFromCorrespondences(const CameraIntrinsics& intrinsics,
                                  const std::vector<glm::dvec3>& points_in_world,
                                  const std::vector<glm::dvec2>& pixels, PoseFit* fit,
                                  std::string* why);

}  // namespace daylit::scene
