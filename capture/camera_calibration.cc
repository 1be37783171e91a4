#include "capture/camera_calibration.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/log.h"

namespace daylit::capture {

CameraCalibration CalibrateCamera(const std::vector<cv::Mat>& views, const std::vector<std::string>& names,
                                  const Chessboard& board) {
  if (views.empty()) ThrowInputError("calibrate-camera: no images");
  const cv::Size pattern(board.inner_columns, board.inner_rows);
  std::vector<cv::Point3f> corners_3d;
  for (int r = 0; r < board.inner_rows; ++r) {
    for (int c = 0; c < board.inner_columns; ++c) {
      corners_3d.emplace_back(static_cast<float>(c * board.square_m), static_cast<float>(r * board.square_m), 0.0f);
    }
  }
  CameraCalibration out;
  out.width = views[0].cols, out.height = views[0].rows;
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (size_t i = 0; i < views.size(); ++i) {
    if (views[i].cols != out.width || views[i].rows != out.height) {
      ThrowInputError("{}: {}x{}, but {} is {}x{}; every view must have the camera's size", names[i], views[i].cols,
                      views[i].rows, names[0], out.width, out.height);
    }
    cv::Mat gray;
    if (views[i].channels() == 1) {
      gray = views[i];
    } else {
      cv::cvtColor(views[i], gray, views[i].channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    }
    std::vector<cv::Point2f> corners;
    if (!cv::findChessboardCorners(gray, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      Log().warn("{}: no {}x{} chessboard found; left out", names[i], board.inner_columns, board.inner_rows);
      continue;
    }
    cv::cornerSubPix(gray, corners, cv::Size(5, 5), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
    object_points.push_back(corners_3d);
    image_points.push_back(corners);
    out.used.push_back(static_cast<int>(i));
  }
  if (out.used.size() < 3) {
    ThrowInputError("calibrate-camera: the {}x{} chessboard was found in {} of {} images; at least 3 are needed",
                    board.inner_columns, board.inner_rows, out.used.size(), views.size());
  }
  cv::Mat k, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  out.rms_px = cv::calibrateCamera(object_points, image_points, cv::Size(out.width, out.height), k, distortion, rvecs, tvecs);
  out.fx = k.at<double>(0, 0), out.fy = k.at<double>(1, 1), out.cx = k.at<double>(0, 2), out.cy = k.at<double>(1, 2);
  out.distortion.assign(distortion.begin<double>(), distortion.end<double>());
  return out;
}

}  // namespace daylit::capture
