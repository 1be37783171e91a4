#include "render/projection.h"

namespace daylit::render {

glm::mat4 ClipFromCamera(const scene::CameraIntrinsics& k, float near_m, float far_m) {
  const double w = k.width, h = k.height;
  // x_ndc = 2(u + 0.5)/w − 1 with u = fx X/Z + cx; y_ndc = 1 − 2(v + 0.5)/h with v = fy Y/Z + cy.
  glm::dmat4 m(0.0);  // column-major: m[column][row]
  m[0][0] = 2.0 * k.fx / w;
  m[2][0] = (2.0 * k.cx + 1.0) / w - 1.0;
  m[1][1] = -2.0 * k.fy / h;
  m[2][1] = 1.0 - (2.0 * k.cy + 1.0) / h;
  m[2][2] = (far_m + near_m) / (far_m - near_m);
  m[3][2] = -2.0 * far_m * near_m / (far_m - near_m);
  m[2][3] = 1.0;
  return glm::mat4(m);
}

glm::mat4 CameraFromWorld(const scene::RigidPose& pose) {
  glm::dmat4 m(pose.rotation);
  m[3] = glm::dvec4(pose.translation, 1.0);
  return glm::mat4(m);
}

}  // namespace daylit::render
