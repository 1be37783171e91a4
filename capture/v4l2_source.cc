#include "capture/v4l2_source.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/log.h"

namespace daylit::capture {
namespace {

int Ioctl(int fd, unsigned long request, void* arg) {
  int r = 0;
  do {
    r = ::ioctl(fd, request, arg);
  } while (r == -1 && errno == EINTR);
  return r;
}

bool Usable(uint32_t fourcc) { return fourcc == V4L2_PIX_FMT_MJPEG || fourcc == V4L2_PIX_FMT_YUYV; }

int64_t Snap(int64_t value, const ControlInfo& c) {
  const int64_t clamped = std::clamp(value, c.minimum, c.maximum);
  const int64_t step = std::max<int64_t>(1, c.step);
  return c.minimum + (clamped - c.minimum) / step * step;
}

}  // namespace

std::string FourccName(uint32_t fourcc) {
  std::string name(4, ' ');
  for (int i = 0; i < 4; ++i) name[static_cast<size_t>(i)] = static_cast<char>((fourcc >> (8 * i)) & 0xff);
  return name;
}

std::optional<V4l2Format> ChooseFormat(const std::vector<V4l2Format>& offered, int width, int height, double fps) {
  std::vector<V4l2Format> usable;
  for (const V4l2Format& f : offered) {
    if (Usable(f.fourcc) && f.width > 0 && f.height > 0) usable.push_back(f);
  }
  if (usable.empty()) return std::nullopt;
  // The size: exact, else the smallest that covers the request, else the largest.
  const auto area = [](const V4l2Format& f) { return static_cast<int64_t>(f.width) * f.height; };
  std::optional<V4l2Format> size;
  for (const V4l2Format& f : usable) {
    if (f.width == width && f.height == height) size = f;
  }
  if (!size) {
    for (const V4l2Format& f : usable) {
      if (f.width >= width && f.height >= height && (!size || area(f) < area(*size))) size = f;
    }
  }
  if (!size) {
    for (const V4l2Format& f : usable) {
      if (!size || area(f) > area(*size)) size = f;
    }
  }
  // At that size: a rate of at least `fps` (the slowest such), else the fastest; YUYV first.
  std::optional<V4l2Format> best;
  const auto better = [&](const V4l2Format& a, const V4l2Format& b) {
    const bool a_fast = a.fps >= fps - 1e-6, b_fast = b.fps >= fps - 1e-6;
    if (a_fast != b_fast) return a_fast;
    if (a_fast && std::abs(a.fps - b.fps) > 1e-6) return a.fps < b.fps;
    if (!a_fast && std::abs(a.fps - b.fps) > 1e-6) return a.fps > b.fps;
    return a.fourcc == V4L2_PIX_FMT_YUYV && b.fourcc != V4L2_PIX_FMT_YUYV;
  };
  for (const V4l2Format& f : usable) {
    if (f.width == size->width && f.height == size->height && (!best || better(f, *best))) best = f;
  }
  return best;
}

std::vector<ControlWrite> PlanControls(const std::map<uint32_t, ControlInfo>& available, const CameraSettings& requested,
                                       std::vector<std::string>* notes) {
  std::vector<ControlWrite> writes;
  const auto find = [&](uint32_t id) -> const ControlInfo* {
    const auto it = available.find(id);
    return it == available.end() ? nullptr : &it->second;
  };
  // One automatic switch and its manual value: (auto id, manual value of the switch), (id, unit).
  const auto lock = [&](uint32_t auto_id, int64_t manual, const char* auto_name, uint32_t id, const char* name,
                        const char* unit, const std::optional<int64_t>& wanted, bool essential) {
    if (find(auto_id) != nullptr) {
      writes.push_back({auto_id, manual, fmt::format("{} off (manual)", auto_name)});
    } else if (essential) {
      notes->push_back(fmt::format("warning: the camera has no {} control; if it adjusts {} by itself, the light "
                                   "will seem to change",
                                   auto_name, name));
    }
    const ControlInfo* c = find(id);
    if (c == nullptr) {
      notes->push_back(fmt::format("the camera has no {} control; {} left as it is", name, name));
      return;
    }
    const int64_t value = Snap(wanted.value_or(c->current), *c);
    if (wanted && value != *wanted) {
      notes->push_back(fmt::format("{} {} is outside [{}, {}] step {}; using {}", name, *wanted, c->minimum, c->maximum,
                                   c->step, value));
    }
    writes.push_back({id, value, fmt::format("{} {}{} ({})", name, value, unit, wanted ? "as asked" : "held from auto")});
  };
  lock(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, "auto exposure", V4L2_CID_EXPOSURE_ABSOLUTE, "exposure",
       " ×100 µs", requested.exposure_100us, true);
  lock(V4L2_CID_AUTOGAIN, 0, "auto gain", V4L2_CID_GAIN, "gain", "", requested.gain, false);
  lock(V4L2_CID_AUTO_WHITE_BALANCE, 0, "auto white balance", V4L2_CID_WHITE_BALANCE_TEMPERATURE, "white balance", " K",
       requested.white_balance_k, true);
  return writes;
}

UtcTime KernelTimestampToUtc(const timeval& stamp, const timespec& monotonic_now, const UtcTime& utc_now) {
  const double age = (static_cast<double>(monotonic_now.tv_sec) - static_cast<double>(stamp.tv_sec)) +
                     (static_cast<double>(monotonic_now.tv_nsec) * 1e-9 - static_cast<double>(stamp.tv_usec) * 1e-6);
  return UtcFromUnixSeconds(UnixSeconds(utc_now) - age);
}

namespace {

class V4l2Source final : public FrameSource {
 public:
  V4l2Source(std::string device, const V4l2Options& options) : device_(std::move(device)), options_(options) {
    Open();
  }
  ~V4l2Source() override { Close(); }

  FrameStatus Next(Frame* frame) override {
    if (fd_ < 0) {
      // Unplugged: try again every second; the pipeline holds its last estimate meanwhile.
      const auto now = std::chrono::steady_clock::now();
      if (now < next_retry_) {
        std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(next_retry_ - now, std::chrono::milliseconds(100)));
        return FrameStatus::kWaiting;
      }
      try {
        Open();
        Log().info("{}: back; streaming again", device_);
      } catch (const InputError&) {
        next_retry_ = now + std::chrono::seconds(1);
        return FrameStatus::kWaiting;
      }
    }
    if (!streaming_) {
      // Streaming starts with the first frame asked for, not at open: the bake between the two
      // would leave the buffers holding frames from before it and the sequence numbers a gap.
      v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (Ioctl(fd_, VIDIOC_STREAMON, &type) < 0) ThrowSystemError("{}: cannot start streaming ({})", device_, std::strerror(errno));
      streaming_ = true;
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, 1000);
    if (ready == 0) return FrameStatus::kWaiting;
    v4l2_buffer buffer{};
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    if (ready < 0 || Ioctl(fd_, VIDIOC_DQBUF, &buffer) < 0) {
      if (errno == EAGAIN) return FrameStatus::kWaiting;
      Log().warn("{}: the camera stopped ({}); retrying every second", device_, std::strerror(errno));
      Close();
      next_retry_ = std::chrono::steady_clock::now() + std::chrono::seconds(1);
      return FrameStatus::kWaiting;
    }
    // Behind the camera: the driver holds newer frames than this one. Take the newest and give
    // the older ones back, so that a pipeline slower than the camera works on what the camera
    // sees now, frames skipped, instead of falling further behind.
    while (options_.newest_only) {
      v4l2_buffer newer{};
      newer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      newer.memory = V4L2_MEMORY_MMAP;
      if (Ioctl(fd_, VIDIOC_DQBUF, &newer) < 0) break;  // EAGAIN: none newer
      CountSequence(buffer.sequence);
      Ioctl(fd_, VIDIOC_QBUF, &buffer);
      ++stats_.skipped;
      buffer = newer;
    }
    CountSequence(buffer.sequence);
    timespec monotonic{};
    ::clock_gettime(CLOCK_MONOTONIC, &monotonic);
    timespec real{};
    ::clock_gettime(CLOCK_REALTIME, &real);
    const UtcTime utc_now = UtcFromUnixSeconds(static_cast<double>(real.tv_sec) + 1e-9 * static_cast<double>(real.tv_nsec));
    frame->index = next_index_++;
    frame->utc = KernelTimestampToUtc(buffer.timestamp, monotonic, utc_now);
    frame->exposure = options_.exposure;
    frame->linear = false;
    frame->rgb.release();  // its own buffer: the last frame's may still be read (Frame::rgb)
    const bool ok = Decode(static_cast<const uint8_t*>(mapped_[buffer.index].first), buffer.bytesused, &frame->rgb);
    Ioctl(fd_, VIDIOC_QBUF, &buffer);
    if (!ok) {
      ++stats_.undecodable;
      return FrameStatus::kUndecodable;
    }
    ++stats_.delivered;
    return FrameStatus::kFrame;
  }

  // Frames the driver never delivered: gaps in the sequence numbers of those it did.
  void CountSequence(uint32_t sequence) {
    if (last_sequence_ >= 0 && sequence > static_cast<uint32_t>(last_sequence_) + 1) {
      stats_.dropped += static_cast<int>(sequence - static_cast<uint32_t>(last_sequence_) - 1);
    }
    last_sequence_ = static_cast<int64_t>(sequence);
  }

  void Seek(int) override { ThrowInputError("{}: a live camera cannot seek", device_); }
  std::string Describe() const override {
    return fmt::format("{} ({} {}x{} at {:g} fps)", device_, FourccName(format_.fourcc), format_.width, format_.height,
                       format_.fps);
  }
  bool live() const override { return true; }

 private:
  void Open() {
    fd_ = ::open(device_.c_str(), O_RDWR | O_NONBLOCK);
    if (fd_ < 0) {
      // No such device is the name the user gave; a device there that will not open (busy, not
      // permitted, failing) is the machine's.
      const int error = errno;
      if (error == ENOENT || error == ENOTDIR || error == ENXIO || error == ENODEV) {
        ThrowInputError("{}: cannot open ({}){}", device_, std::strerror(error),
                        error == ENOENT ? "; is the camera plugged in?" : "");
      }
      ThrowSystemError("{}: cannot open ({}){}", device_, std::strerror(error),
                       error == EBUSY ? "; another program is using it" : error == EACCES ? "; is this user in the video group?" : "");
    }
    try {
      Configure();
    } catch (...) {
      Close();
      throw;
    }
  }

  void Configure() {
    v4l2_capability cap{};
    if (Ioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0) ThrowInputError("{}: not a V4L2 device", device_);
    const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) ThrowInputError("{}: {} cannot capture video", device_, reinterpret_cast<char*>(cap.card));
    if (!(caps & V4L2_CAP_STREAMING)) ThrowInputError("{}: {} cannot stream (mmap)", device_, reinterpret_cast<char*>(cap.card));
    const std::optional<V4l2Format> chosen = ChooseFormat(Offered(), options_.width, options_.height, options_.fps);
    if (!chosen) ThrowInputError("{}: offers neither MJPEG nor YUYV", device_);
    v4l2_format fmt{};
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    fmt.fmt.pix.width = static_cast<uint32_t>(chosen->width);
    fmt.fmt.pix.height = static_cast<uint32_t>(chosen->height);
    fmt.fmt.pix.pixelformat = chosen->fourcc;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (Ioctl(fd_, VIDIOC_S_FMT, &fmt) < 0) ThrowSystemError("{}: cannot set {} {}x{} ({})", device_, FourccName(chosen->fourcc), chosen->width, chosen->height, std::strerror(errno));
    format_ = {fmt.fmt.pix.pixelformat, static_cast<int>(fmt.fmt.pix.width), static_cast<int>(fmt.fmt.pix.height), chosen->fps};
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    parm.parm.capture.timeperframe = {1000, static_cast<uint32_t>(std::lround(1000.0 * chosen->fps))};
    if (Ioctl(fd_, VIDIOC_S_PARM, &parm) == 0 && parm.parm.capture.timeperframe.numerator > 0) {
      format_.fps = static_cast<double>(parm.parm.capture.timeperframe.denominator) / parm.parm.capture.timeperframe.numerator;
    }
    Log().info("{}: {}, {} {}x{} at {:g} fps", device_, reinterpret_cast<char*>(cap.card), FourccName(format_.fourcc),
               format_.width, format_.height, format_.fps);
    LockControls();
    StartStreaming();
  }

  std::vector<V4l2Format> Offered() const {
    std::vector<V4l2Format> offered;
    v4l2_fmtdesc desc{};
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    for (desc.index = 0; Ioctl(fd_, VIDIOC_ENUM_FMT, &desc) == 0; ++desc.index) {
      if (!Usable(desc.pixelformat)) continue;
      v4l2_frmsizeenum size{};
      size.pixel_format = desc.pixelformat;
      for (size.index = 0; Ioctl(fd_, VIDIOC_ENUM_FRAMESIZES, &size) == 0; ++size.index) {
        if (size.type != V4L2_FRMSIZE_TYPE_DISCRETE) {
          offered.push_back({desc.pixelformat, options_.width, options_.height, options_.fps});  // any size
          break;
        }
        v4l2_frmivalenum interval{};
        interval.pixel_format = desc.pixelformat;
        interval.width = size.discrete.width, interval.height = size.discrete.height;
        bool any = false;
        for (interval.index = 0; Ioctl(fd_, VIDIOC_ENUM_FRAMEINTERVALS, &interval) == 0; ++interval.index) {
          if (interval.type != V4L2_FRMIVAL_TYPE_DISCRETE || interval.discrete.numerator == 0) continue;
          offered.push_back({desc.pixelformat, static_cast<int>(size.discrete.width), static_cast<int>(size.discrete.height),
                             static_cast<double>(interval.discrete.denominator) / interval.discrete.numerator});
          any = true;
        }
        if (!any) offered.push_back({desc.pixelformat, static_cast<int>(size.discrete.width), static_cast<int>(size.discrete.height), options_.fps});
      }
    }
    return offered;
  }

  void LockControls() {
    std::map<uint32_t, ControlInfo> available;
    for (const uint32_t id : {V4L2_CID_EXPOSURE_AUTO, V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_CID_AUTOGAIN, V4L2_CID_GAIN,
                              V4L2_CID_AUTO_WHITE_BALANCE, V4L2_CID_WHITE_BALANCE_TEMPERATURE}) {
      v4l2_queryctrl q{};
      q.id = id;
      if (Ioctl(fd_, VIDIOC_QUERYCTRL, &q) < 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED)) continue;
      v4l2_control c{};
      c.id = id;
      Ioctl(fd_, VIDIOC_G_CTRL, &c);
      available[id] = {q.minimum, q.maximum, q.step, q.default_value, c.value};
    }
    std::vector<std::string> notes;
    const std::vector<ControlWrite> plan = PlanControls(available, options_.settings, &notes);
    for (const std::string& n : notes) {
      if (n.rfind("warning: ", 0) == 0) {
        Log().warn("{}: {}", device_, n.substr(9));
      } else {
        Log().info("{}: {}", device_, n);
      }
    }
    for (const ControlWrite& w : plan) {
      v4l2_control c{w.id, static_cast<int32_t>(w.value)};
      if (Ioctl(fd_, VIDIOC_S_CTRL, &c) < 0) {
        Log().warn("{}: cannot set {}: {}", device_, w.what, std::strerror(errno));
        continue;
      }
      v4l2_control back{w.id, 0};
      Ioctl(fd_, VIDIOC_G_CTRL, &back);
      Log().info("{}: {}; reads back {}", device_, w.what, back.value);
      if (back.value != c.value) Log().warn("{}: {} did not take: the camera reports {}", device_, w.what, back.value);
    }
  }

  void StartStreaming() {
    v4l2_requestbuffers request{};
    request.count = static_cast<uint32_t>(options_.buffers);
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    if (Ioctl(fd_, VIDIOC_REQBUFS, &request) < 0 || request.count < 2) ThrowSystemError("{}: cannot get mmap buffers ({})", device_, std::strerror(errno));
    for (uint32_t i = 0; i < request.count; ++i) {
      v4l2_buffer buffer{};
      buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      buffer.memory = V4L2_MEMORY_MMAP;
      buffer.index = i;
      if (Ioctl(fd_, VIDIOC_QUERYBUF, &buffer) < 0) ThrowSystemError("{}: cannot query buffer {} ({})", device_, i, std::strerror(errno));
      void* data = ::mmap(nullptr, buffer.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, buffer.m.offset);
      if (data == MAP_FAILED) ThrowSystemError("{}: cannot map buffer {} ({})", device_, i, std::strerror(errno));
      mapped_.emplace_back(data, buffer.length);
      if (Ioctl(fd_, VIDIOC_QBUF, &buffer) < 0) ThrowSystemError("{}: cannot queue buffer {} ({})", device_, i, std::strerror(errno));
    }
    streaming_ = false;  // STREAMON with the first Next()
    last_sequence_ = -1;
  }

  bool Decode(const uint8_t* data, uint32_t bytes, cv::Mat* rgb) const {
    cv::Mat decoded;
    if (format_.fourcc == V4L2_PIX_FMT_MJPEG) {
      const cv::Mat bgr = cv::imdecode(cv::Mat(1, static_cast<int>(bytes), CV_8UC1, const_cast<uint8_t*>(data)), cv::IMREAD_COLOR);
      if (bgr.empty()) return false;
      cv::cvtColor(bgr, decoded, cv::COLOR_BGR2RGB);
    } else {
      if (bytes < static_cast<uint32_t>(format_.width * format_.height * 2)) return false;
      const cv::Mat yuyv(format_.height, format_.width, CV_8UC2, const_cast<uint8_t*>(data));
      cv::cvtColor(yuyv, decoded, cv::COLOR_YUV2RGB_YUYV);
    }
    decoded.convertTo(*rgb, CV_32FC3, 1.0 / 255.0);
    return true;
  }

  void Close() {
    if (fd_ < 0) return;
    v4l2_buf_type type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    Ioctl(fd_, VIDIOC_STREAMOFF, &type);
    for (const auto& [data, length] : mapped_) ::munmap(data, length);
    mapped_.clear();
    ::close(fd_);
    fd_ = -1;
  }

  std::string device_;
  V4l2Options options_;
  int fd_ = -1;
  V4l2Format format_;
  std::vector<std::pair<void*, size_t>> mapped_;
  int64_t last_sequence_ = -1;
  bool streaming_ = false;
  int next_index_ = 0;
  std::chrono::steady_clock::time_point next_retry_;
};

}  // namespace

std::unique_ptr<FrameSource> OpenV4l2Source(const std::string& device, const V4l2Options& options) {
  return std::make_unique<V4l2Source>(device, options);
}

}  // namespace daylit::capture
