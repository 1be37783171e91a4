// The bundled courtyard-a recording and its bake, as the recording tests use them: loaded once
// per test binary, the bake from one cache in the build tree that the tests share.
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

inline const BundledCourtyard& Courtyard() {
  static const BundledCourtyard courtyard = [] {
    SetLogVerbosity(0);
    BundledCourtyard c{scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a"), {}};
    bool loaded = false;
    c.bake = bake::BakeOrLoad(c.scene, bake::BakeOptions{}, DAYLIT_BINARY_DIR "/test-cache/courtyard-a", &loaded);
    return c;
  }();
  return courtyard;
}

// A measured figure under `key` ("courtyard-a/volume/p95_error"), in gtest's output for
// scripts/results.sh to put on docs/results.md: fractions for errors, seconds for times.
inline void RecordFigure(const std::string& key, double value) {
  ::testing::Test::RecordProperty(key, fmt::format("{}", value));
}

}  // namespace daylit::testing
