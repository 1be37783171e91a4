// Light probes as the light-source approximation reads them (issue 8): Radiance .hdr or OpenEXR,
// a 2:1 latitude-longitude map in daylit's frame (docs/design.md), or a square angular
// (mirror-ball) map in Debevec's layout, converted. Checked for values no radiance can have and
// for a clipped light source.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "scene/hdr_image.h"

namespace daylit::lightfit {

struct Probe {
  HdrImage map;                // lat-long, 2:1
  bool converted_from_angular = false;
  std::vector<std::string> warnings;  // for the caller to log
};

// Reads and checks a probe. Throws InputError naming the file for an unreadable file, a shape
// that is neither 2:1 nor square, and NaN, infinite or negative values (with their count and
// the first texel). A brightest source that looks clipped is a warning.
Probe LoadProbe(const std::filesystem::path& path);

// A square angular map (Debevec's light probe gallery: the centre looks forward, the radius is
// linear in the angle from forward, the rim is straight back) resampled to a width × height
// lat-long map in daylit's frame, in which the gallery's forward is +Y and its up +Z. Each texel
// averages 3×3 bilinear samples.
HdrImage AngularToLatLong(const HdrImage& angular, int width, int height);

// A warning when the map's brightest source looks clipped: at least `min_texels` texels exactly at
// the peak luminance while the peak is over 50 times the median (a bright, flat-topped source: a
// saturated sun or lamp, whose irradiance is then too low). Empty when it does not. An unclipped
// peak is one texel; RGBE's 0.4% steps put up to 6 texels of Uffizi's bright sky on one value, a
// sun clipped a thousandfold on a 1024×512 map 30 or more.
std::string ClippedSourceWarning(const HdrImage& map, int min_texels = 12);

}  // namespace daylit::lightfit
