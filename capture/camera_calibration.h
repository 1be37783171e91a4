// Camera intrinsics from views of a chessboard (OpenCV: findChessboardCorners, cornerSubPix,
// calibrateCamera), for the intrinsics block of scene.json.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace daylit::capture {

struct Chessboard {
  int inner_columns = 9;  // inner corners along a row
  int inner_rows = 6;
  double square_m = 0.025;
};

struct CameraCalibration {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::vector<double> distortion;  // k1, k2, p1, p2, k3
  double rms_px = 0.0;             // reprojection error over all corners
  std::vector<int> used;           // indices of the views whose board was found
};

// Calibrates from 8-bit views (any channel count), all of one size. Views where the board is not
// found are left out (and listed as not used). Throws InputError, naming `names[i]`, for a view
// of another size, and when fewer than 3 views show the board.
CameraCalibration CalibrateCamera(const std::vector<cv::Mat>& views, const std::vector<std::string>& names,
                                  const Chessboard& board);

}  // namespace daylit::capture
