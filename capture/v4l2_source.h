// Live frames from a V4L2 camera (linux/videodev2.h): capabilities, format negotiation (MJPEG or
// YUYV, decoded with OpenCV), mmap streaming with a small buffer queue, kernel timestamps in UTC,
// and the radiometric controls (exposure, gain, white balance) switched to manual, set, read back
// and logged, because a camera that adjusts itself makes the sun seem to change. A camera that
// goes away mid-stream is reopened every second; meanwhile Next() says kWaiting.
//
// The decisions that need no kernel (format choice, the control plan, timestamp conversion) are
// separate functions, tested without a device.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"

struct timeval;
struct timespec;

namespace daylit::capture {

struct V4l2Format {
  uint32_t fourcc = 0;  // V4L2_PIX_FMT_MJPEG or V4L2_PIX_FMT_YUYV
  int width = 0, height = 0;
  double fps = 0.0;
};

std::string FourccName(uint32_t fourcc);

// The format to capture in, among those the device offers: the requested size if offered (else
// the smallest larger one, else the largest), at a rate of at least `fps` when one is offered
// (else the fastest). At the chosen size and rate YUYV wins over MJPEG: it is uncompressed, so
// no JPEG blocking in the pixels the estimation reads. Empty when nothing usable is offered.
std::optional<V4l2Format> ChooseFormat(const std::vector<V4l2Format>& offered, int width, int height, double fps);

// A control as VIDIOC_QUERYCTRL describes it, with its current value.
struct ControlInfo {
  int64_t minimum = 0, maximum = 0, step = 1, default_value = 0, current = 0;
};

// What the user asks for; an absent value is held at what the camera's automatic had reached.
struct CameraSettings {
  std::optional<int64_t> exposure_100us;   // V4L2_CID_EXPOSURE_ABSOLUTE, in 100 µs
  std::optional<int64_t> gain;             // V4L2_CID_GAIN, device units
  std::optional<int64_t> white_balance_k;  // V4L2_CID_WHITE_BALANCE_TEMPERATURE
};

struct ControlWrite {
  uint32_t id = 0;
  int64_t value = 0;
  std::string what;  // "exposure 300 (×100 µs), held from auto"
};

// The writes that lock the camera's radiometry, in order: automatic exposure to manual
// (V4L2_EXPOSURE_MANUAL), then the exposure; automatic gain off, then the gain; automatic white
// balance off, then the temperature. A value is clamped to the control's range and step (noted
// in `notes`). A control the camera lacks is skipped with a note; so is an automatic switch it
// lacks, and if exposure stays automatic that is a warning in `notes` starting "warning:".
std::vector<ControlWrite> PlanControls(const std::map<uint32_t, ControlInfo>& available, const CameraSettings& requested,
                                       std::vector<std::string>* notes);

// A buffer's kernel timestamp (CLOCK_MONOTONIC, as V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC says) in
// UTC, from one simultaneous reading of both clocks.
UtcTime KernelTimestampToUtc(const timeval& stamp, const timespec& monotonic_now, const UtcTime& utc_now);

struct V4l2Options {
  int width = 1280, height = 720;
  double fps = 30.0;
  CameraSettings settings;
  double exposure = 1.0;  // scene.json's camera.exposure: linear pixel = k · radiance
  int buffers = 4;        // mmap buffers queued in the driver
  // Each Next() takes the newest frame the driver holds, giving older ones back unread (counted
  // as skipped): for a pipeline that must not fall behind the camera. Off: every frame, in
  // order (daylit record).
  bool newest_only = false;
};

// Opens `device` and configures it; streaming starts with the first Next(). Throws InputError "<device>: ..." when it does not exist,
// is not a V4L2 capture device, or offers neither MJPEG nor YUYV; SystemError when a device that is
// there fails (busy, not permitted, an ioctl or mmap refused).
std::unique_ptr<FrameSource> OpenV4l2Source(const std::string& device, const V4l2Options& options);

}  // namespace daylit::capture
