#include "scene/envmap_probe.h"

#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include <opencv2/imgcodecs.hpp>

#include "base/error.h"

namespace daylit::scene {

EnvMapHeader ProbeEnvMap(const std::filesystem::path& path) {
  EnvMapHeader header;
  if (path.extension() == ".exr") {
    try {
      Imf::InputFile file(path.c_str());
      const Imath::Box2i window = file.header().dataWindow();
      header.width = window.max.x - window.min.x + 1;
      header.height = window.max.y - window.min.y + 1;
      for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
        header.channels += it.name();
      }
    } catch (const std::exception& e) {
      ThrowInputError("{}: not a readable OpenEXR file ({})", path.string(), e.what());
    }
    header.format = "OpenEXR";
    return header;
  }
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) ThrowInputError("{}: not a readable Radiance HDR file", path.string());
  header.width = image.cols;
  header.height = image.rows;
  header.channels = image.channels() == 3 ? "RGB" : std::to_string(image.channels());
  header.format = "Radiance HDR";
  return header;
}

}  // namespace daylit::scene
