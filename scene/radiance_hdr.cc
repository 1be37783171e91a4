#include "scene/radiance_hdr.h"

// stb_image with its HDR decoder only, every function static to this file (so that no other
// copy of stb_image in the process, e.g. a glTF library's, binds to this reduced one). Compiled
// without warnings (scene/CMakeLists.txt): the code is stb's.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_HDR
#define STBI_FAILURE_USERMSG
#include <stb_image.h>

#include <cstdio>
#include <memory>

namespace daylit::scene {

bool DecodeRadianceHdr(const std::filesystem::path& path, int* width, int* height, std::vector<float>* rgb, std::string* why) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) {
    *why = "cannot be opened";
    return false;
  }
  if (!stbi_is_hdr_from_file(file.get())) {
    *why = "no Radiance signature";
    return false;
  }
  int channels = 0;
  std::unique_ptr<float, void (*)(void*)> pixels(stbi_loadf_from_file(file.get(), width, height, &channels, 3), &stbi_image_free);
  if (!pixels) {
    *why = stbi_failure_reason() != nullptr ? stbi_failure_reason() : "cannot be decoded";
    return false;
  }
  rgb->assign(pixels.get(), pixels.get() + static_cast<size_t>(*width) * static_cast<size_t>(*height) * 3);
  return true;
}

}  // namespace daylit::scene
