// The geodetic frame of a scene: scene coordinates (metres, +Z up, +Y at compass azimuth
// north_azimuth_deg) <-> local east-north-up at the scene origin <-> WGS84 geodetic.
#pragma once

#include <GeographicLib/LocalCartesian.hpp>
#include <glm/glm.hpp>

#include "sunmodel/solar_position.h"

namespace daylit::sunmodel {

class SceneGeoFrame {
 public:
  // `origin`: WGS84 position of the scene origin; `north_azimuth_deg`: compass azimuth
  // (clockwise from true north) of the scene's +Y axis.
  SceneGeoFrame(const GeoSite& origin, double north_azimuth_deg);

  const glm::dmat3& enu_from_scene() const { return enu_from_scene_; }

  // Unit vector in scene coordinates toward compass azimuth `azimuth_deg` (east of north) and
  // zenith angle `zenith_deg`. For the sun, pass the apparent zenith: that is where light comes from.
  glm::dvec3 DirectionInScene(double azimuth_deg, double zenith_deg) const;

  // Inverse of DirectionInScene for any non-zero vector; azimuth in [0, 360).
  void AzimuthZenithOf(const glm::dvec3& dir_in_scene, double* azimuth_deg,
                       double* zenith_deg) const;

  // WGS84 position of a scene point (through GeographicLib's local Cartesian frame), and back.
  GeoSite GeodeticOf(const glm::dvec3& point_in_scene) const;
  glm::dvec3 SceneOf(const GeoSite& geodetic) const;

 private:
  GeographicLib::LocalCartesian enu_from_geodetic_;
  glm::dmat3 enu_from_scene_;
  glm::dmat3 scene_from_enu_;
};

}  // namespace daylit::sunmodel
