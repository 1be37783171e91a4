// OpenCV's pinhole camera (x right, y down, z forward; pixel centres at integer coordinates) as
// OpenGL matrices, so that a world point lands on the pixel CameraModel::Project gives (lens
// distortion aside: the renderer draws with the undistorted pinhole).
#pragma once

#include <glm/glm.hpp>

#include "scene/camera.h"

namespace daylit::render {

// Clip coordinates from camera coordinates, for a width × height viewport: window x = u + 0.5 and
// window y = height − (v + 0.5) for the pixel (u, v) OpenCV projects to; depth maps [near, far].
glm::mat4 ClipFromCamera(const scene::CameraIntrinsics& k, float near_m, float far_m);

// Camera coordinates from world (scene) coordinates.
glm::mat4 CameraFromWorld(const scene::RigidPose& pose);

}  // namespace daylit::render
