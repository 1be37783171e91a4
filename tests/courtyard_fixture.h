// The bundled recordings and their bakes, as the recording tests use them: loaded once per test
// binary, each bake from one cache in the build tree that the tests share.
#pragma once

#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "bake/bake.h"
#include "base/log.h"
#include "scene/scene.h"

namespace daylit::testing {

struct BundledCourtyard {
  scene::Scene scene;
  bake::SceneBake bake;
};

// A bundled recording (recordings/<name>) and its bake, from the build tree's test cache.
inline BundledCourtyard LoadBundled(const std::string& name) {
  SetLogVerbosity(0);
  BundledCourtyard c{scene::LoadScene(std::string(DAYLIT_SOURCE_DIR "/recordings/") + name), {}};
  bool loaded = false;
  c.bake = bake::BakeOrLoad(c.scene, bake::BakeOptions{}, std::string(DAYLIT_BINARY_DIR "/test-cache/") + name, &loaded);
  return c;
}

inline const BundledCourtyard& Courtyard() {
  static const BundledCourtyard courtyard = LoadBundled("courtyard-a");
  return courtyard;
}

// courtyard-c: Santiago in June, an arcade lit mostly by reflected light (issue 18).
inline const BundledCourtyard& CourtyardC() {
  static const BundledCourtyard courtyard = LoadBundled("courtyard-c");
  return courtyard;
}

// courtyard-b: Florence in September, a portico whose back wall is lit by reflected light (issue 37).
inline const BundledCourtyard& CourtyardB() {
  static const BundledCourtyard courtyard = LoadBundled("courtyard-b");
  return courtyard;
}

// courtyard-e: as real scenes are (issue 38): a sketched model, windows, clutter, glossy materials,
// two bursts under a photographed sky.
inline const BundledCourtyard& CourtyardE() {
  static const BundledCourtyard courtyard = LoadBundled("courtyard-e");
  return courtyard;
}

// A measured figure under `key` ("courtyard-a/volume/p95_error"), in gtest's output for
// scripts/results.sh to put on docs/results.md: fractions for errors, seconds for times.
inline void RecordFigure(const std::string& key, double value) {
  ::testing::Test::RecordProperty(key, fmt::format("{}", value));
}

}  // namespace daylit::testing
