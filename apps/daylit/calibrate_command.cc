// daylit calibrate-response and calibrate-camera: a camera's response curve from an exposure
// bracket, its intrinsics from chessboard views (docs/capture.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "apps/daylit/commands.h"
#include "base/atomic_file.h"
#include "base/error.h"
#include "base/files.h"
#include "base/log.h"
#include "capture/camera_calibration.h"
#include "capture/response.h"
#include "report/plot.h"

namespace daylit::app {
namespace {

cv::Mat ReadEightBit(const std::string& file, int flags) {
  RequireRegularFile(file);
  const cv::Mat image = cv::imread(file, flags);
  if (image.empty()) ThrowInputError("{}: cannot be decoded as an image", file);
  if (image.depth() != CV_8U) ThrowInputError("{}: not an 8-bit image", file);
  return image;
}

struct ResponseOptions {
  std::vector<std::string> images;
  std::vector<float> seconds;
  std::string out = "response.csv";
};

void RunCalibrateResponse(const ResponseOptions& o) {
  if (o.images.size() < 2) ThrowInputError("calibrate-response: an exposure bracket needs at least 2 images");
  if (o.seconds.size() != o.images.size()) {
    ThrowInputError("--times: {} exposure times for {} images", o.seconds.size(), o.images.size());
  }
  // A bracket needs different exposures: equal times or identical images leave the curve
  // undetermined (the solve gives NaN).
  for (size_t i = 1; i < o.images.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (o.seconds[i] == o.seconds[j]) {
        ThrowInputError("--times: {} and {} have the same exposure time {} s; a bracket needs different ones",
                        o.images[j], o.images[i], o.seconds[i]);
      }
    }
  }
  {
    std::vector<std::filesystem::path> inputs(o.images.begin(), o.images.end());
    const std::filesystem::path png = std::filesystem::path(o.out).replace_extension(".png");
    RefuseInputsAsOutputs(inputs, {}, {{"--out", o.out}, {"--out's plot", png}});
    RefuseSharedOutputs({{"--out", o.out}, {"--out's plot", png}});
  }
  std::vector<cv::Mat> images;
  for (size_t i = 0; i < o.images.size(); ++i) {
    if (!(o.seconds[i] > 0.0f)) ThrowInputError("--times: {} s for {} is not an exposure time", o.seconds[i], o.images[i]);
    images.push_back(ReadEightBit(o.images[i], cv::IMREAD_COLOR));
    if (images[i].size() != images[0].size()) {
      ThrowInputError("{}: {}x{}, but {} is {}x{}; a bracket is one view", o.images[i], images[i].cols, images[i].rows,
                      o.images[0], images[0].cols, images[0].rows);
    }
  }
  if (std::all_of(images.begin() + 1, images.end(), [&](const cv::Mat& m) { return cv::norm(m, images[0], cv::NORM_INF) == 0; })) {
    ThrowInputError("{}: every image of the bracket is the same; the exposures did not change the picture", o.images[0]);
  }
  capture::ResponseTable table = capture::CalibrateResponse(images, o.seconds);
  for (size_t c = 0; c < 3; ++c) {
    for (const double v : table.linear[c]) {
      if (!std::isfinite(v)) ThrowInputError("{}: the bracket does not determine a response curve (it came out NaN)", o.images[0]);
    }
  }
  table.file = o.out;
  capture::WriteResponseTable(o.out, table);
  report::PlotOptions options{"camera response (Debevec & Malik), linear value per 8-bit code", "code", "linear", 900, 420};
  report::LinePlot plot(options);
  for (size_t c = 0; c < 3; ++c) {
    report::Series s{std::string(1, "RGB"[c]), {}, {}, c == 0 ? std::array<int, 3>{214, 39, 40}
                                                         : c == 1 ? std::array<int, 3>{44, 160, 44}
                                                                  : std::array<int, 3>{31, 119, 180}};
    for (size_t i = 0; i < 256; ++i) s.x.push_back(static_cast<double>(i)), s.y.push_back(table.linear[c][i]);
    plot.Add(s);
  }
  const std::filesystem::path png = std::filesystem::path(o.out).replace_extension(".png");
  report::WritePng(png, {plot.Render()});
  fmt::print("code 64 / 128 / 192 -> linear R {:.4f} {:.4f} {:.4f}, G {:.4f} {:.4f} {:.4f}, B {:.4f} {:.4f} {:.4f}\n",
             table.linear[0][64], table.linear[0][128], table.linear[0][192], table.linear[1][64], table.linear[1][128],
             table.linear[1][192], table.linear[2][64], table.linear[2][128], table.linear[2][192]);
  Log().info("wrote {} and {}; name it in scene.json as \"response\": {{\"curve\": \"{}\"}}", o.out, png.string(),
             std::filesystem::path(o.out).filename().string());
}

struct CameraOptions {
  std::vector<std::string> images;
  std::string board = "9x6";
  double square_m = 0.025;
  std::string out = "intrinsics.json";
};

void RunCalibrateCamera(const CameraOptions& o) {
  capture::Chessboard board;
  char x = 0;
  int used = 0;
  if (std::sscanf(o.board.c_str(), "%d%c%d%n", &board.inner_columns, &x, &board.inner_rows, &used) != 3 || x != 'x' ||
      static_cast<size_t>(used) != o.board.size() || board.inner_columns < 2 || board.inner_rows < 2) {
    ThrowInputError("--board: '{}' is not COLSxROWS of inner corners, e.g. 9x6", o.board);
  }
  RefuseInputsAsOutputs(std::vector<std::filesystem::path>(o.images.begin(), o.images.end()), {}, {{"--out", o.out}});
  // OpenCV's corner search allocates per corner and takes minutes on a huge pattern; a printed
  // board has a few dozen corners a side.
  constexpr int kMaxCorners = 100;
  if (board.inner_columns > kMaxCorners || board.inner_rows > kMaxCorners) {
    ThrowInputError("--board: {} inner corners; at most {} a side", o.board, kMaxCorners);
  }
  if (!(o.square_m > 0.0)) ThrowInputError("--square: {} m is not a square size", o.square_m);
  board.square_m = o.square_m;
  std::vector<cv::Mat> views;
  for (const std::string& file : o.images) views.push_back(ReadEightBit(file, cv::IMREAD_GRAYSCALE));
  const capture::CameraCalibration c = capture::CalibrateCamera(views, o.images, board);
  const nlohmann::json camera = {{"width", c.width}, {"height", c.height}, {"fx", c.fx},         {"fy", c.fy},
                                 {"cx", c.cx},       {"cy", c.cy},         {"distortion", c.distortion}};
  WriteFileAtomically(o.out, nlohmann::json{{"camera", camera}}.dump(2) + "\n");
  fmt::print("{} of {} views used; reprojection error {:.3f} px (RMS)\nfx {:.2f}  fy {:.2f}  cx {:.2f}  cy {:.2f}\n",
             c.used.size(), views.size(), c.rms_px, c.fx, c.fy, c.cx, c.cy);
  Log().info("wrote {}: the intrinsics block of scene.json's camera (the pose comes from world_to_camera or "
             "correspondences)", o.out);
}

}  // namespace

void AddCalibrateCommands(CLI::App& app) {
  auto response = std::make_shared<ResponseOptions>();
  CLI::App* r = app.add_subcommand("calibrate-response", "A camera's response curve from an exposure bracket (Debevec & Malik)");
  r->add_option("images", response->images, "8-bit images of one static view at different exposures")->required();
  r->add_option("--times", response->seconds, "Exposure time of each image in seconds, comma separated")
      ->required()->delimiter(',');
  r->add_option("--out", response->out, "Response table CSV (default response.csv; the plot gets .png)");
  r->callback([response] { RunCalibrateResponse(*response); });

  auto camera = std::make_shared<CameraOptions>();
  CLI::App* c = app.add_subcommand("calibrate-camera", "Camera intrinsics from chessboard images (OpenCV)");
  c->add_option("images", camera->images, "Images of a chessboard in different poses")->required();
  c->add_option("--board", camera->board, "Inner corners, COLSxROWS (default 9x6)");
  c->add_option("--square", camera->square_m, "Square size in metres (default 0.025)");
  c->add_option("--out", camera->out, "JSON with the camera intrinsics block (default intrinsics.json)");
  c->callback([camera] { RunCalibrateCamera(*camera); });
}

}  // namespace daylit::app
