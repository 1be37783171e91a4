#include "pipeline/video_output.h"

#include <system_error>

#include "base/atomic_file.h"
#include "base/error.h"

namespace daylit::pipeline {

namespace fs = std::filesystem;

void CheckVideoName(const fs::path& out) {
  const std::string ext = out.extension().string();
  if (ext != ".mp4" && ext != ".mkv") ThrowInputError("--out: {} must end in .mp4 or .mkv", out.string());
}

VideoOutput::VideoOutput(const fs::path& out, const scene::Scene& scene) : out_(out) {
  CheckVideoName(out);
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  if (!fs::is_directory(dir)) ThrowInputError("--out: {}: no such folder", dir.string());
  partial_ = TemporarySibling(out);
  partial_ += out.extension();  // the container is chosen by the extension
  try {
    writer_.emplace(partial_, scene.intrinsics.width, scene.intrinsics.height, scene::NominalFps(scene), scene.response);
  } catch (const InputError& e) {
    std::error_code ec;
    fs::remove(partial_, ec);
    ThrowInputError("--out: cannot write {} ({})", out.string(), e.what());
  } catch (...) {  // the machine's (no libx264, a full disk): nothing half-written left either
    std::error_code ec;
    fs::remove(partial_, ec);
    throw;
  }
}

VideoOutput::~VideoOutput() {
  writer_.reset();
  std::error_code ec;
  if (!committed_) fs::remove(partial_, ec);
}

void VideoOutput::Commit() {
  writer_->Finish();
  CommitTemporary(partial_, out_);
  committed_ = true;
}

}  // namespace daylit::pipeline
