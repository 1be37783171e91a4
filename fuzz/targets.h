// The parsers of untrusted input as fuzz targets: each takes one input (the bytes of a file a
// user or another tool may hand daylit), feeds it through the same entry point the commands use,
// and accepts only InputError as the outcome of bad bytes. Anything else (another exception, a
// crash, a sanitizer report) aborts: it is a bug. libFuzzer drives them (fuzz_main.cc,
// scripts/fuzz.sh); fuzz_regression_test replays every input kept in fuzz/regressions/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string_view>
#include <vector>

namespace daylit::fuzz {

struct Target {
  std::string_view name;
  // Sets up what the input is read against (a small recording, a bake); once per process.
  std::function<void()> init;
  // One input; returns normally for good input and for bad input that gets an InputError.
  std::function<void(const uint8_t* data, size_t size)> run;
  // Writes small seed inputs into a folder (the seed corpus beside the bundled files).
  std::function<void(const std::filesystem::path& dir)> write_seeds;
};

// Every target, by name: scene_json, obj, csv, exr, hdr, gltf, bake_cache, video (a recording's
// H.264 through capture::VideoDecoder), http_request (the lighting server's request heads).
const std::vector<Target>& Targets();
const Target& FindTarget(std::string_view name);

// Runs `body`; an InputError is the expected end of bad input, any other exception aborts.
void ExpectOnlyInputErrors(std::string_view target, const std::function<void()>& body);

}  // namespace daylit::fuzz
