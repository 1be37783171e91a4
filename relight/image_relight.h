// Image relighting (seed 004, "getting the sun to set"): the camera frame under another sun and
// another light. For a Lambertian point the radiance is ρ/π·E, so the frame (linear) times the
// ratio of two irradiance maps from the camera's viewpoint, E_new / E_now, is the frame under the
// new light; the albedo, texture included, cancels. Each E is the model the estimation fits
// (estimation/transfer.h), per pixel and channel, with cast shadows for its own sun:
//
//   E = E_sun·T_sun + E_clear·T_clear + E_overcast·T_overcast
//
// T by relight::SurfaceTerms over the bake's camera G-buffer (a shadow ray per pixel and sun; the
// light the courtyard reflects from one pixel in 4×4). Pixels outside the model (the sky) keep
// their value, or follow the sky: the ratio of the sky's radiance toward them under each sun and
// light (the captured sky's shape plus the uniform overcast part).
//
// Deep shadow: where E_now is below `floor` × the irradiance open level ground receives now
// (E_sun·max(0, l_z) + E_sky, per channel), E_now is taken as that, so the ratio stays bounded
// and the camera's noise there is not amplified without limit. Such pixels are counted.
#pragma once

#include <string>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "relight/env_relight.h"
#include "relight/surface_terms.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::relight {

enum class SkyPixels { kKeep, kFollow };

struct ImageRelightOptions {
  SkyPixels sky = SkyPixels::kKeep;
  float floor = 0.02f;  // of open level ground's irradiance now
  estimation::TransferOptions transfer;
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// One lighting of the scene: the unit sun (scene coordinates; z ≤ 0: below the horizon, no sun
// light) and the model's three lights.
struct SceneLight {
  glm::vec3 sun_dir{0.0f, 0.0f, 1.0f};
  LightParts parts;
};

// Per pixel (row-major), the terms of one moment: E = parts.sun·sun + parts.clear·clear +
// parts.overcast·overcast. Sky pixels have sun = 0, clear = the sky's shape toward them per unit
// DHI, overcast = 1/π.
struct PixelTerms {
  std::vector<glm::vec3> sun, clear, overcast;
};
enum PixelKind : uint8_t { kModelPixel = 0, kSkyPixel = 1, kKeptPixel = 2 };

// What the ratio needs per frame, besides the lights: both moments' terms and what each pixel is.
struct RatioTerms {
  int width = 0, height = 0;
  PixelTerms now, next;
  std::vector<uint8_t> kind;       // PixelKind
  glm::vec3 now_sun{0.0f, 0.0f, 1.0f};
  float floor = 0.02f;             // ImageRelightOptions::floor

  // The floor under E_now, per channel: `floor` × (E_sun·max(0, l_z) + E_clear + E_overcast).
  glm::vec3 FloorOf(const LightParts& now) const;
};

struct RelightStats {
  size_t model_pixels = 0;
  size_t clamped = 0;  // model pixels whose E_now was below the floor (any channel)
};

// The CPU path, on all cores: `rgb` (linear, width × height × 3) times E_new / E_now in place.
RelightStats ApplyRatio(const RatioTerms& terms, const LightParts& now, const LightParts& next, float* rgb);
// The ratio E_new / E_now itself, RGB per pixel (1 for kept pixels).
RelightStats RatioOf(const RatioTerms& terms, const LightParts& now, const LightParts& next, float* ratio);

class ImageRelighter {
 public:
  // `scene`, `bake` and `caster` (over the scene's model) must outlive this.
  ImageRelighter(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                 ImageRelightOptions options = {});

  // The suns of now and of the new light; each one's terms are recomputed when it is not the
  // direction they were last made for (the pipeline hands on a new one only when the sun has
  // moved: scene::SunTracker's one rule). Returns true if either was.
  bool SetSuns(const glm::vec3& now, const glm::vec3& next);

  // Multiplies `rgb` (linear, width × height × 3) by E_new / E_now in place (ApplyRatio).
  RelightStats Apply(const LightParts& now, const LightParts& next, float* rgb) const {
    return ApplyRatio(terms_, now, next, rgb);
  }

  // The terms for the current suns.
  const RatioTerms& terms() const { return terms_; }
  int width() const { return terms_.width; }
  int height() const { return terms_.height; }

 private:
  void Fill(const glm::vec3& sun_dir, PixelTerms* terms);

  SurfaceTerms surface_;
  std::vector<glm::vec3> sky_dirs_;  // per sky pixel (in sky_pixels_ order), the camera ray
  std::vector<uint32_t> sky_pixels_;
  std::optional<glm::vec3> now_sun_, next_sun_;
  RatioTerms terms_;
  std::vector<estimation::Transfer> scratch_;
};

// The sunlit/shadowed layout of a linear frame (radiance units) under `light`: over the camera's
// diffuse pixels that face the sun (n·l > 0.25) and where the sun would at least double the sky's
// light, 1 where the pixel is closer to the model's shadowed radiance than to its sunlit one
// (ρ/π from the bake's albedo), 0 where closer to the sunlit one; 255 where not decided.
std::vector<uint8_t> ShadowLayout(const bake::CameraGBuffer& g, const PixelTerms& terms, const SceneLight& light,
                                  const float* rgb);
// Intersection over union of two layouts' shadowed pixels, over the pixels both decided.
double ShadowIoU(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

// The mean relative error |a − b| / b over the camera's diffuse pixels (averaged over RGB; pixels
// whose b is below 1e-3 of its median luminance left out).
double DiffuseError(const bake::CameraGBuffer& g, const float* a, const float* b);

// A clear-sky model for the light at another sun elevation (ASHRAE 1985, the monthly constants of
// its Handbook of Fundamentals): DNI = A·exp(−B / sin h), DHI = C·DNI. Returns the factors
// (on E_sun, on E_sky) from elevation `from_deg` to `to_deg` in month `month` (1–12). With the sun
// down at either end: (0, 1), no sun and the sky as it is (the model has no twilight).
glm::dvec2 ClearSkyFactors(double from_deg, double to_deg, int month);

}  // namespace daylit::relight
