#include "scene/envmap_probe.h"

#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>

#include "base/error.h"
#include "scene/hdr_image.h"

namespace daylit::scene {

EnvMapHeader ProbeEnvMap(const std::filesystem::path& path) {
  EnvMapHeader header;
  if (path.extension() == ".exr") {
    CheckExrClaimedSize(path, 2);
    try {
      Imf::InputFile file(path.c_str());
      const Imath::Box2i window = file.header().dataWindow();
      const int64_t width = int64_t{window.max.x} - window.min.x + 1, height = int64_t{window.max.y} - window.min.y + 1;
      int channels = 0;
      for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
        header.channels += it.name();
        ++channels;
      }
      CheckClaimedSize(path, width, height, 2 * static_cast<int64_t>(channels));
      header.width = static_cast<int>(width);
      header.height = static_cast<int>(height);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      ThrowInputError("{}: not a readable OpenEXR file ({})", path.string(), e.what());
    }
    header.format = "OpenEXR";
    return header;
  }
  // The size from the header alone: decoding a map to learn its size cost a second, and a hostile
  // header's size was allocated.
  ReadRadianceSize(path, &header.width, &header.height);
  CheckClaimedSize(path, header.width, header.height, 4);
  header.channels = "RGB";
  header.format = "Radiance HDR";
  return header;
}

}  // namespace daylit::scene
