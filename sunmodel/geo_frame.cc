#include "sunmodel/geo_frame.h"

#include <cmath>
#include <numbers>

namespace daylit::sunmodel {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

}  // namespace

SceneGeoFrame::SceneGeoFrame(const GeoSite& origin, double north_azimuth_deg)
    : enu_from_geodetic_(origin.latitude_deg, origin.longitude_deg, origin.elevation_m) {
  // Scene +Y looks at compass azimuth N: ENU (sin N, cos N, 0); scene +X is 90° clockwise of it.
  const double n = north_azimuth_deg * kRadPerDeg;
  const glm::dvec3 x_in_enu(std::cos(n), -std::sin(n), 0.0);
  const glm::dvec3 y_in_enu(std::sin(n), std::cos(n), 0.0);
  enu_from_scene_ = glm::dmat3(x_in_enu, y_in_enu, glm::dvec3(0.0, 0.0, 1.0));
  scene_from_enu_ = glm::transpose(enu_from_scene_);
}

glm::dvec3 SceneGeoFrame::DirectionInScene(double azimuth_deg, double zenith_deg) const {
  const double az = azimuth_deg * kRadPerDeg;
  const double zen = zenith_deg * kRadPerDeg;
  const glm::dvec3 dir_in_enu(std::sin(zen) * std::sin(az), std::sin(zen) * std::cos(az),
                              std::cos(zen));
  return scene_from_enu_ * dir_in_enu;
}

void SceneGeoFrame::AzimuthZenithOf(const glm::dvec3& dir_in_scene, double* azimuth_deg,
                                    double* zenith_deg) const {
  const glm::dvec3 d = glm::normalize(enu_from_scene_ * dir_in_scene);
  *zenith_deg = std::acos(std::clamp(d.z, -1.0, 1.0)) / kRadPerDeg;
  *azimuth_deg = std::fmod(std::atan2(d.x, d.y) / kRadPerDeg + 360.0, 360.0);
}

GeoSite SceneGeoFrame::GeodeticOf(const glm::dvec3& point_in_scene) const {
  const glm::dvec3 enu = enu_from_scene_ * point_in_scene;
  GeoSite site;
  enu_from_geodetic_.Reverse(enu.x, enu.y, enu.z, site.latitude_deg, site.longitude_deg,
                             site.elevation_m);
  return site;
}

glm::dvec3 SceneGeoFrame::SceneOf(const GeoSite& geodetic) const {
  glm::dvec3 enu;
  enu_from_geodetic_.Forward(geodetic.latitude_deg, geodetic.longitude_deg, geodetic.elevation_m,
                             enu.x, enu.y, enu.z);
  return scene_from_enu_ * enu;
}

}  // namespace daylit::sunmodel
