// A userspace V4L2 capture device for tests: preloaded into a daylit process (LD_PRELOAD), it
// answers open, ioctl, mmap, munmap, poll and close for one device path the way a UVC webcam's
// driver does (linux/videodev2.h), serving a recording's video frames as YUYV or MJPEG. There is
// no camera on the machines that test daylit; this stands in for the kernel interface, not for
// daylit's code, which runs unchanged. What it does not cover: docs/capture.md.
//
// Set by the environment (tests/live_device_test.cc):
//   DAYLIT_FAKECAM_DEVICE   the path it answers for (every other path goes to the real calls)
//   DAYLIT_FAKECAM_VIDEO    the video whose frames it serves (decoded once, looped)
//   DAYLIT_FAKECAM_FRAMES   how many of its frames (default 30)
//   DAYLIT_FAKECAM_FORMATS  "YUYV,MJPG" (default), in ENUM_FMT's order
//   DAYLIT_FAKECAM_DROP     every Nth sensor frame is lost before it reaches a buffer (0: none)
//   DAYLIT_FAKECAM_UNPLUG   "K,S": at sensor frame K the device goes (ENODEV, then ENOENT on open)
//                           for S seconds, then the path is back
//   DAYLIT_FAKECAM_STUCK    a control name (exposure, gain, white_balance) whose S_CTRL succeeds
//                           but that keeps its old value, as some cameras' firmware does
//   DAYLIT_FAKECAM_LOG      a CSV it appends to: one row per frame handed out by DQBUF ("frame",
//                           sequence, source frame, CLOCK_MONOTONIC and CLOCK_REALTIME at its
//                           capture, format), per frame lost ("lost", sequence, why: injected or
//                           no buffer queued) and per control write ("control", name, the value
//                           asked, the value kept)
#include <dlfcn.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace {

template <typename F>
F Real(const char* name) {
  return reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
}

double Now(clockid_t clock) {
  timespec t{};
  ::clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::string Env(const char* name, const char* fallback = "") {
  const char* v = std::getenv(name);
  return v != nullptr ? v : fallback;
}

struct Control {
  const char* name;
  v4l2_ctrl_type type;
  int32_t minimum, maximum, step, default_value, value;
};

struct Size {
  int width, height;
};

// One open of the device: its format, buffers and stream.
struct Stream {
  uint32_t fourcc = V4L2_PIX_FMT_YUYV;
  Size size{0, 0};
  uint32_t interval_denominator = 30;  // timeperframe 1/30 s
  bool streaming = false;
  struct Buffer {
    void* data = nullptr;
    size_t length = 0;
    bool queued = false;  // owned by the driver, empty
    bool done = false;    // filled, waiting for DQBUF
    v4l2_buffer info{};
    std::string log_row;  // what the log says of its frame once it is handed out (DQBUF)
  };
  std::vector<Buffer> buffers;
  std::vector<uint32_t> done_order;  // filled buffers, oldest first
  double start = 0.0;                // CLOCK_MONOTONIC at STREAMON
  uint64_t next_frame = 0;           // the sensor's next frame (its sequence number)
};

class FakeCamera {
 public:
  FakeCamera() {
    path_ = Env("DAYLIT_FAKECAM_DEVICE");
    drop_every_ = std::atoi(Env("DAYLIT_FAKECAM_DROP", "0").c_str());
    const std::string unplug = Env("DAYLIT_FAKECAM_UNPLUG");
    if (!unplug.empty()) std::sscanf(unplug.c_str(), "%lld,%lf", &unplug_frame_, &unplug_seconds_);
    stuck_ = Env("DAYLIT_FAKECAM_STUCK");
    log_path_ = Env("DAYLIT_FAKECAM_LOG");
    const std::string formats = Env("DAYLIT_FAKECAM_FORMATS", "YUYV,MJPG");
    if (formats.find("YUYV") != std::string::npos) formats_.push_back(V4L2_PIX_FMT_YUYV);
    if (formats.find("MJPG") != std::string::npos) formats_.push_back(V4L2_PIX_FMT_MJPEG);
    // A UVC webcam's usual controls: exposure in 100 µs units, gain, white balance in K (step 10).
    controls_[V4L2_CID_EXPOSURE_AUTO] = {"exposure_auto", V4L2_CTRL_TYPE_MENU, 0, 3, 1, 3, 3};
    controls_[V4L2_CID_EXPOSURE_ABSOLUTE] = {"exposure", V4L2_CTRL_TYPE_INTEGER, 3, 2047, 1, 250, 250};
    controls_[V4L2_CID_AUTOGAIN] = {"gain_auto", V4L2_CTRL_TYPE_BOOLEAN, 0, 1, 1, 1, 1};
    controls_[V4L2_CID_GAIN] = {"gain", V4L2_CTRL_TYPE_INTEGER, 0, 255, 1, 64, 64};
    controls_[V4L2_CID_AUTO_WHITE_BALANCE] = {"white_balance_auto", V4L2_CTRL_TYPE_BOOLEAN, 0, 1, 1, 1, 1};
    controls_[V4L2_CID_WHITE_BALANCE_TEMPERATURE] = {"white_balance", V4L2_CTRL_TYPE_INTEGER, 2800, 6500, 10, 4600, 4600};
  }

  bool Handles(const char* path) const { return !path_.empty() && path != nullptr && path_ == path; }
  bool Owns(int fd) {
    std::lock_guard<std::recursive_mutex> lock(mutex_);
    return streams_.count(fd) > 0;
  }

  int Open() {
    std::lock_guard<std::recursive_mutex> lock(mutex_);
    if (Now(CLOCK_MONOTONIC) < gone_until_) return Fail(ENOENT);
    LoadFrames();
    if (frames_.empty()) return Fail(EIO);
    static const auto real_eventfd = Real<int (*)(unsigned, int)>("eventfd");
    const int fd = real_eventfd(0, EFD_CLOEXEC);
    if (fd < 0) return -1;
    Stream s;
    s.size = sizes_.front();
    streams_[fd] = s;
    return fd;
  }

  int Close(int fd) {
    {
      std::lock_guard<std::recursive_mutex> lock(mutex_);
      auto it = streams_.find(fd);
      if (it != streams_.end()) {
        for (Stream::Buffer& b : it->second.buffers) {
          if (b.data != nullptr) Real<int (*)(void*, size_t)>("munmap")(b.data, b.length);
        }
        streams_.erase(it);
      }
    }
    return Real<int (*)(int)>("close")(fd);
  }

  int Ioctl(int fd, unsigned long request, void* arg);
  void* Mmap(int fd, size_t length, off_t offset);
  bool Unmap(void* address);  // true if it was one of the buffers (kept: REQBUFS frees them)
  int Poll(int fd, int timeout_ms);

 private:
  static int Fail(int error) {
    errno = error;
    return -1;
  }
  bool Gone() const { return Now(CLOCK_MONOTONIC) < gone_until_; }

  // The served frames, at each offered size, as YUYV and MJPEG bytes.
  void LoadFrames() {
    if (!frames_.empty()) return;
    cv::VideoCapture video(Env("DAYLIT_FAKECAM_VIDEO"));
    const int count = std::max(1, std::atoi(Env("DAYLIT_FAKECAM_FRAMES", "30").c_str()));
    cv::Mat bgr;
    while (static_cast<int>(frames_.size()) < count && video.read(bgr)) {
      if (sizes_.empty()) {
        sizes_ = {{bgr.cols, bgr.rows}, {bgr.cols / 2 / 2 * 2, bgr.rows / 2}};
      }
      std::map<uint32_t, std::vector<uint8_t>> encoded;
      for (const Size& size : sizes_) {
        cv::Mat scaled;
        cv::resize(bgr, scaled, cv::Size(size.width, size.height), 0, 0, cv::INTER_AREA);
        encoded[Key(V4L2_PIX_FMT_YUYV, size)] = ToYuyv(scaled);
        std::vector<uint8_t> jpeg;
        cv::imencode(".jpg", scaled, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
        encoded[Key(V4L2_PIX_FMT_MJPEG, size)] = std::move(jpeg);
      }
      frames_.push_back(std::move(encoded));
    }
  }
  static uint32_t Key(uint32_t fourcc, const Size& s) { return fourcc ^ static_cast<uint32_t>(s.width * 7919 + s.height); }

  // BGR to YUYV 4:2:2 with BT.601's studio range, the inverse of what OpenCV's YUV2RGB_YUYV does.
  static std::vector<uint8_t> ToYuyv(const cv::Mat& bgr) {
    std::vector<uint8_t> out(static_cast<size_t>(bgr.cols) * bgr.rows * 2);
    const auto clamp = [](double v) { return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L)); };
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x + 1 < bgr.cols; x += 2) {
        const cv::Vec3b a = bgr.at<cv::Vec3b>(y, x), b = bgr.at<cv::Vec3b>(y, x + 1);
        const auto luma = [](const cv::Vec3b& p) { return 16.0 + 0.257 * p[2] + 0.504 * p[1] + 0.098 * p[0]; };
        const double r = 0.5 * (a[2] + b[2]), g = 0.5 * (a[1] + b[1]), bl = 0.5 * (a[0] + b[0]);
        uint8_t* o = &out[(static_cast<size_t>(y) * bgr.cols + x) * 2];
        o[0] = clamp(luma(a));
        o[1] = clamp(128.0 - 0.148 * r - 0.291 * g + 0.439 * bl);
        o[2] = clamp(luma(b));
        o[3] = clamp(128.0 + 0.439 * r - 0.368 * g - 0.071 * bl);
      }
    }
    return out;
  }

  size_t ImageBytes(const Stream& s) const {
    if (s.fourcc == V4L2_PIX_FMT_YUYV) return static_cast<size_t>(s.size.width) * s.size.height * 2;
    size_t most = 0;  // MJPEG: room for the largest frame
    for (const auto& f : frames_) most = std::max(most, f.at(Key(V4L2_PIX_FMT_MJPEG, s.size)).size());
    return most + 4096;
  }

  // Runs the sensor up to now: each frame whose time has come goes into the oldest queued empty
  // buffer, or is lost when there is none (a client too slow), or by DAYLIT_FAKECAM_DROP.
  void Produce(Stream& s) {
    const double now = Now(CLOCK_MONOTONIC), real_now = Now(CLOCK_REALTIME);
    const double period = 1.0 / s.interval_denominator;
    while (s.start + static_cast<double>(s.next_frame) * period <= now) {
      const uint64_t sequence = s.next_frame++;
      if (unplug_frame_ >= 0 && static_cast<long long>(sequence) == unplug_frame_ && gone_until_ == 0.0) {
        gone_until_ = now + unplug_seconds_;  // once
        return;
      }
      if (drop_every_ > 0 && (sequence + 1) % static_cast<uint64_t>(drop_every_) == 0) {
        Log(fmt("lost,%llu,injected", static_cast<unsigned long long>(sequence)));
        continue;
      }
      auto empty = std::find_if(s.buffers.begin(), s.buffers.end(), [](const Stream::Buffer& b) { return b.queued && !b.done; });
      if (empty == s.buffers.end()) {  // no buffer: the frame is lost, its sequence number too
        Log(fmt("lost,%llu,no buffer", static_cast<unsigned long long>(sequence)));
        continue;
      }
      const size_t source = sequence % frames_.size();
      const std::vector<uint8_t>& bytes = frames_[source].at(Key(s.fourcc, s.size));
      const size_t n = std::min(bytes.size(), empty->length);
      std::memcpy(empty->data, bytes.data(), n);
      const double captured = s.start + static_cast<double>(sequence) * period;
      empty->done = true;
      empty->info.bytesused = static_cast<uint32_t>(n);
      empty->info.sequence = static_cast<uint32_t>(sequence);
      empty->info.timestamp.tv_sec = static_cast<time_t>(std::floor(captured));
      empty->info.timestamp.tv_usec = static_cast<suseconds_t>(std::lround((captured - std::floor(captured)) * 1e6));
      empty->info.flags = V4L2_BUF_FLAG_MAPPED | V4L2_BUF_FLAG_DONE | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
      s.done_order.push_back(empty->info.index);
      empty->log_row = fmt("frame,%llu,%zu,%.6f,%.6f,%s", static_cast<unsigned long long>(sequence), source, captured,
                           real_now - (now - captured), s.fourcc == V4L2_PIX_FMT_YUYV ? "YUYV" : "MJPG");
    }
  }

  static std::string fmt(const char* format, ...) {
    char line[512];
    va_list args;
    va_start(args, format);
    std::vsnprintf(line, sizeof(line), format, args);
    va_end(args);
    return line;
  }
  void Log(const std::string& line) const {
    if (log_path_.empty()) return;
    if (FILE* f = std::fopen(log_path_.c_str(), "a")) {
      std::fprintf(f, "%s\n", line.c_str());
      std::fclose(f);
    }
  }

  std::recursive_mutex mutex_;  // decoding the video at open calls open, mmap and close again
  std::string path_, stuck_, log_path_;
  int drop_every_ = 0;
  long long unplug_frame_ = -1;
  double unplug_seconds_ = 0.0, gone_until_ = 0.0;
  std::vector<uint32_t> formats_;
  std::vector<Size> sizes_;
  std::map<uint32_t, Control> controls_;
  std::vector<std::map<uint32_t, std::vector<uint8_t>>> frames_;
  std::map<int, Stream> streams_;
};

int FakeCamera::Ioctl(int fd, unsigned long request, void* arg) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  Stream& s = streams_.at(fd);
  if (Gone()) return Fail(ENODEV);
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      *cap = {};
      std::snprintf(reinterpret_cast<char*>(cap->driver), sizeof(cap->driver), "uvcvideo");
      std::snprintf(reinterpret_cast<char*>(cap->card), sizeof(cap->card), "daylit test camera");
      std::snprintf(reinterpret_cast<char*>(cap->bus_info), sizeof(cap->bus_info), "usb-daylit-1");
      cap->version = (6u << 16) | (1u << 8);
      cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT;
      cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto* d = static_cast<v4l2_fmtdesc*>(arg);
      if (d->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || d->index >= formats_.size()) return Fail(EINVAL);
      d->pixelformat = formats_[d->index];
      d->flags = d->pixelformat == V4L2_PIX_FMT_MJPEG ? V4L2_FMT_FLAG_COMPRESSED : 0;
      std::snprintf(reinterpret_cast<char*>(d->description), sizeof(d->description), "%s",
                    d->pixelformat == V4L2_PIX_FMT_MJPEG ? "Motion-JPEG" : "YUYV 4:2:2");
      return 0;
    }
    case VIDIOC_ENUM_FRAMESIZES: {
      auto* f = static_cast<v4l2_frmsizeenum*>(arg);
      if (std::find(formats_.begin(), formats_.end(), f->pixel_format) == formats_.end() || f->index >= sizes_.size()) {
        return Fail(EINVAL);
      }
      f->type = V4L2_FRMSIZE_TYPE_DISCRETE;
      f->discrete = {static_cast<uint32_t>(sizes_[f->index].width), static_cast<uint32_t>(sizes_[f->index].height)};
      return 0;
    }
    case VIDIOC_ENUM_FRAMEINTERVALS: {
      auto* f = static_cast<v4l2_frmivalenum*>(arg);
      const bool known = std::any_of(sizes_.begin(), sizes_.end(), [&](const Size& z) {
        return static_cast<uint32_t>(z.width) == f->width && static_cast<uint32_t>(z.height) == f->height;
      });
      if (!known || f->index >= 2) return Fail(EINVAL);
      f->type = V4L2_FRMIVAL_TYPE_DISCRETE;
      f->discrete = {1, f->index == 0 ? 30u : 15u};
      return 0;
    }
    case VIDIOC_G_FMT:
    case VIDIOC_S_FMT:
    case VIDIOC_TRY_FMT: {
      auto* f = static_cast<v4l2_format*>(arg);
      if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request != VIDIOC_G_FMT) {
        if (request == VIDIOC_S_FMT && s.streaming) return Fail(EBUSY);
        // As drivers do: never refuse, adjust to the nearest offered format and size.
        Stream t = s;
        t.fourcc = std::find(formats_.begin(), formats_.end(), f->fmt.pix.pixelformat) != formats_.end() ? f->fmt.pix.pixelformat
                                                                                                      : formats_.front();
        const auto distance = [&](const Size& z) {
          return std::abs(z.width - static_cast<int>(f->fmt.pix.width)) + std::abs(z.height - static_cast<int>(f->fmt.pix.height));
        };
        t.size = *std::min_element(sizes_.begin(), sizes_.end(), [&](const Size& a, const Size& b) { return distance(a) < distance(b); });
        if (request == VIDIOC_S_FMT) s.fourcc = t.fourcc, s.size = t.size;
        f->fmt.pix.pixelformat = t.fourcc;
        f->fmt.pix.width = static_cast<uint32_t>(t.size.width);
        f->fmt.pix.height = static_cast<uint32_t>(t.size.height);
      } else {
        f->fmt.pix.pixelformat = s.fourcc;
        f->fmt.pix.width = static_cast<uint32_t>(s.size.width);
        f->fmt.pix.height = static_cast<uint32_t>(s.size.height);
      }
      f->fmt.pix.field = V4L2_FIELD_NONE;
      f->fmt.pix.bytesperline = f->fmt.pix.pixelformat == V4L2_PIX_FMT_YUYV ? f->fmt.pix.width * 2 : 0;
      f->fmt.pix.colorspace = V4L2_COLORSPACE_SRGB;
      Stream sized = s;
      sized.fourcc = f->fmt.pix.pixelformat, sized.size = {static_cast<int>(f->fmt.pix.width), static_cast<int>(f->fmt.pix.height)};
      f->fmt.pix.sizeimage = static_cast<uint32_t>(ImageBytes(sized));
      return 0;
    }
    case VIDIOC_G_PARM:
    case VIDIOC_S_PARM: {
      auto* p = static_cast<v4l2_streamparm*>(arg);
      if (p->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_S_PARM) {
        if (s.streaming) return Fail(EBUSY);
        const v4l2_fract asked = p->parm.capture.timeperframe;
        const double fps = asked.numerator > 0 ? static_cast<double>(asked.denominator) / asked.numerator : 30.0;
        s.interval_denominator = fps > 22.5 ? 30 : 15;  // the nearest offered interval
      }
      p->parm.capture = {};
      p->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
      p->parm.capture.timeperframe = {1, s.interval_denominator};
      p->parm.capture.readbuffers = 0;
      return 0;
    }
    case VIDIOC_QUERYCTRL: {
      auto* q = static_cast<v4l2_queryctrl*>(arg);
      const auto it = controls_.find(q->id);
      if (it == controls_.end()) return Fail(EINVAL);
      const Control& c = it->second;
      q->type = c.type;
      std::snprintf(reinterpret_cast<char*>(q->name), sizeof(q->name), "%s", c.name);
      q->minimum = c.minimum, q->maximum = c.maximum, q->step = c.step, q->default_value = c.default_value;
      q->flags = 0;
      return 0;
    }
    case VIDIOC_G_CTRL:
    case VIDIOC_S_CTRL: {
      auto* v = static_cast<v4l2_control*>(arg);
      const auto it = controls_.find(v->id);
      if (it == controls_.end()) return Fail(EINVAL);
      Control& c = it->second;
      if (request == VIDIOC_G_CTRL) {
        v->value = c.value;
        return 0;
      }
      // The control framework's rules: a menu or boolean value out of range is refused; an
      // integer one is clamped and rounded to the step. uvcvideo refuses manual exposure while
      // auto exposure is on (EACCES), and white balance while auto white balance is.
      if (c.type != V4L2_CTRL_TYPE_INTEGER && (v->value < c.minimum || v->value > c.maximum)) return Fail(EINVAL);
      if ((v->id == V4L2_CID_EXPOSURE_ABSOLUTE && controls_[V4L2_CID_EXPOSURE_AUTO].value != V4L2_EXPOSURE_MANUAL) ||
          (v->id == V4L2_CID_WHITE_BALANCE_TEMPERATURE && controls_[V4L2_CID_AUTO_WHITE_BALANCE].value != 0) ||
          (v->id == V4L2_CID_GAIN && controls_[V4L2_CID_AUTOGAIN].value != 0)) {
        return Fail(EACCES);
      }
      const int32_t clamped = std::clamp(v->value, c.minimum, c.maximum);
      const int32_t kept = c.minimum + (clamped - c.minimum + c.step / 2) / c.step * c.step;
      if (stuck_ != c.name) c.value = kept;
      Log(fmt("control,%s,%d,%d", c.name, v->value, c.value));
      v->value = kept;
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* r = static_cast<v4l2_requestbuffers*>(arg);
      if (r->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || r->memory != V4L2_MEMORY_MMAP) return Fail(EINVAL);
      if (s.streaming) return Fail(EBUSY);
      for (Stream::Buffer& b : s.buffers) {
        if (b.data != nullptr) Real<int (*)(void*, size_t)>("munmap")(b.data, b.length);
      }
      s.buffers.clear();
      s.done_order.clear();
      r->count = std::min<uint32_t>(r->count, 32);
      if (r->count > 0) r->count = std::max<uint32_t>(r->count, 2);
      const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
      const size_t length = (ImageBytes(s) + page - 1) / page * page;
      static const auto real_mmap = Real<void* (*)(void*, size_t, int, int, int, off_t)>("mmap");
      for (uint32_t i = 0; i < r->count; ++i) {
        Stream::Buffer b;
        b.length = length;
        b.data = real_mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        b.info.index = i;
        b.info.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        b.info.memory = V4L2_MEMORY_MMAP;
        b.info.length = static_cast<uint32_t>(length);
        b.info.m.offset = static_cast<uint32_t>(i * length);
        s.buffers.push_back(b);
      }
      r->capabilities = V4L2_BUF_CAP_SUPPORTS_MMAP;
      return 0;
    }
    case VIDIOC_QUERYBUF:
    case VIDIOC_QBUF:
    case VIDIOC_DQBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || b->memory != V4L2_MEMORY_MMAP) return Fail(EINVAL);
      if (request == VIDIOC_DQBUF) {
        if (!s.streaming) return Fail(EINVAL);
        Produce(s);
        if (Gone()) return Fail(ENODEV);
        if (s.done_order.empty()) return Fail(EAGAIN);  // the device is always opened O_NONBLOCK here
        Stream::Buffer& done = s.buffers[s.done_order.front()];
        s.done_order.erase(s.done_order.begin());
        done.done = done.queued = false;
        Log(done.log_row);
        *b = done.info;
        return 0;
      }
      if (b->index >= s.buffers.size()) return Fail(EINVAL);
      Stream::Buffer& buffer = s.buffers[b->index];
      if (request == VIDIOC_QBUF) {
        if (buffer.queued) return Fail(EINVAL);
        buffer.queued = true;
        buffer.done = false;
      }
      *b = buffer.info;
      b->flags = V4L2_BUF_FLAG_MAPPED | (buffer.queued ? V4L2_BUF_FLAG_QUEUED : 0);
      return 0;
    }
    case VIDIOC_STREAMON:
    case VIDIOC_STREAMOFF: {
      if (*static_cast<int*>(arg) != V4L2_BUF_TYPE_VIDEO_CAPTURE) return Fail(EINVAL);
      if (request == VIDIOC_STREAMON) {
        if (s.buffers.empty()) return Fail(EINVAL);
        if (!s.streaming) s.streaming = true, s.start = Now(CLOCK_MONOTONIC), s.next_frame = 0;
      } else {
        // STREAMOFF returns every buffer to the application, dequeued.
        s.streaming = false;
        for (Stream::Buffer& b : s.buffers) b.queued = b.done = false;
        s.done_order.clear();
      }
      return 0;
    }
    default:
      return Fail(ENOTTY);  // what the kernel answers an ioctl the driver does not know
  }
}

void* FakeCamera::Mmap(int fd, size_t length, off_t offset) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  Stream& s = streams_.at(fd);
  for (Stream::Buffer& b : s.buffers) {
    if (static_cast<off_t>(b.info.m.offset) == offset && length <= b.length) return b.data;
  }
  errno = EINVAL;
  return MAP_FAILED;
}

bool FakeCamera::Unmap(void* address) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  for (auto& [fd, s] : streams_) {
    for (Stream::Buffer& b : s.buffers) {
      if (b.data == address) return true;  // freed with the buffers (REQBUFS 0 or close)
    }
  }
  return false;
}

int FakeCamera::Poll(int fd, int timeout_ms) {
  const double deadline = Now(CLOCK_MONOTONIC) + (timeout_ms < 0 ? 1e9 : timeout_ms * 1e-3);
  for (;;) {
    {
      std::lock_guard<std::recursive_mutex> lock(mutex_);
      Stream& s = streams_.at(fd);
      if (Gone()) return 1;  // POLLERR: the device went away
      if (s.streaming) {
        Produce(s);
        if (Gone() || !s.done_order.empty()) return 1;
      }
    }
    if (Now(CLOCK_MONOTONIC) >= deadline) return 0;
    ::usleep(1000);
  }
}

FakeCamera& Camera() {
  static FakeCamera* camera = new FakeCamera;
  return *camera;
}

}  // namespace

extern "C" {

namespace {
// open and open64: the device's path to the camera, any other to the real call of that name.
int OpenPath(const char* real_name, const char* path, int flags, va_list args) {
  const mode_t mode = (flags & (O_CREAT | O_TMPFILE)) ? static_cast<mode_t>(va_arg(args, int)) : 0;
  if (Camera().Handles(path)) return Camera().Open();
  const auto real = Real<int (*)(const char*, int, ...)>(real_name);
  return real(path, flags, mode);
}
}  // namespace

int open(const char* path, int flags, ...) {
  va_list args;
  va_start(args, flags);
  const int fd = OpenPath("open", path, flags, args);
  va_end(args);
  return fd;
}

int open64(const char* path, int flags, ...) {
  va_list args;
  va_start(args, flags);
  const int fd = OpenPath("open64", path, flags, args);
  va_end(args);
  return fd;
}

int close(int fd) {
  if (Camera().Owns(fd)) return Camera().Close(fd);
  static const auto real = Real<int (*)(int)>("close");
  return real(fd);
}

int ioctl(int fd, unsigned long request, ...) {
  va_list args;
  va_start(args, request);
  void* arg = va_arg(args, void*);
  va_end(args);
  if (Camera().Owns(fd)) return Camera().Ioctl(fd, request, arg);
  static const auto real = Real<int (*)(int, unsigned long, ...)>("ioctl");
  return real(fd, request, arg);
}

void* mmap(void* address, size_t length, int protection, int flags, int fd, off_t offset) {
  if (fd >= 0 && Camera().Owns(fd)) return Camera().Mmap(fd, length, offset);
  static const auto real = Real<void* (*)(void*, size_t, int, int, int, off_t)>("mmap");
  return real(address, length, protection, flags, fd, offset);
}

void* mmap64(void* address, size_t length, int protection, int flags, int fd, off_t offset) {
  return mmap(address, length, protection, flags, fd, offset);
}

int munmap(void* address, size_t length) {
  if (Camera().Unmap(address)) return 0;
  static const auto real = Real<int (*)(void*, size_t)>("munmap");
  return real(address, length);
}

int poll(pollfd* fds, nfds_t n, int timeout_ms) {
  if (n == 1 && Camera().Owns(fds[0].fd)) {
    const int ready = Camera().Poll(fds[0].fd, timeout_ms);
    fds[0].revents = ready > 0 ? POLLIN : 0;
    return ready;
  }
  static const auto real = Real<int (*)(pollfd*, nfds_t, int)>("poll");
  return real(fds, n, timeout_ms);
}

}  // extern "C"
