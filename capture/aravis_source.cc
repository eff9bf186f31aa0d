// GigE Vision / USB3 Vision camera source through Aravis 0.8. Without Aravis
// (KINCAL_HAVE_ARAVIS undefined) the source reports kUnsupported.

#include <sstream>

#include "capture/frame_source.h"
#include "capture/pixel_convert.h"

#ifdef KINCAL_HAVE_ARAVIS
#include <arv.h>
#include <time.h>

#include <cstring>
#endif

namespace kincal::capture {

#ifdef KINCAL_HAVE_ARAVIS

bool HaveAravis() { return true; }

namespace {

// Takes ownership of *error and returns its message ("" when none).
std::string TakeError(GError** error) {
  if (*error == nullptr) return "";
  std::string msg = (*error)->message ? (*error)->message : "unknown error";
  g_clear_error(error);
  return msg;
}

Status::Kind KindOfError(const GError* error) {
  if (error != nullptr && error->domain == ARV_DEVICE_ERROR) {
    switch (error->code) {
      case ARV_DEVICE_ERROR_NOT_FOUND:
      case ARV_DEVICE_ERROR_NOT_CONNECTED:
        return Status::Kind::kNotFound;
      case ARV_DEVICE_ERROR_NOT_CONTROLLER:
        return Status::Kind::kBusy;
      case ARV_DEVICE_ERROR_TIMEOUT:
        return Status::Kind::kTimeout;
      case ARV_DEVICE_ERROR_FEATURE_NOT_FOUND:
      case ARV_DEVICE_ERROR_WRONG_FEATURE:
      case ARV_DEVICE_ERROR_INVALID_PARAMETER:
        return Status::Kind::kUnsupported;
      default:
        break;
    }
  }
  return Status::Kind::kIoError;
}

// GenICam name of the pixel formats kincal converts ("" for others).
const char* PixelFormatName(ArvPixelFormat f) {
  struct Entry {
    ArvPixelFormat format;
    const char* name;
  };
  static const Entry kTable[] = {
      {ARV_PIXEL_FORMAT_MONO_8, "Mono8"},
      {ARV_PIXEL_FORMAT_MONO_10, "Mono10"},
      {ARV_PIXEL_FORMAT_MONO_12, "Mono12"},
      {ARV_PIXEL_FORMAT_MONO_16, "Mono16"},
      {ARV_PIXEL_FORMAT_BAYER_RG_8, "BayerRG8"},
      {ARV_PIXEL_FORMAT_BAYER_GR_8, "BayerGR8"},
      {ARV_PIXEL_FORMAT_BAYER_GB_8, "BayerGB8"},
      {ARV_PIXEL_FORMAT_BAYER_BG_8, "BayerBG8"},
      {ARV_PIXEL_FORMAT_BAYER_RG_10, "BayerRG10"},
      {ARV_PIXEL_FORMAT_BAYER_GR_10, "BayerGR10"},
      {ARV_PIXEL_FORMAT_BAYER_GB_10, "BayerGB10"},
      {ARV_PIXEL_FORMAT_BAYER_BG_10, "BayerBG10"},
      {ARV_PIXEL_FORMAT_BAYER_RG_12, "BayerRG12"},
      {ARV_PIXEL_FORMAT_BAYER_GR_12, "BayerGR12"},
      {ARV_PIXEL_FORMAT_BAYER_GB_12, "BayerGB12"},
      {ARV_PIXEL_FORMAT_BAYER_BG_12, "BayerBG12"},
      {ARV_PIXEL_FORMAT_BAYER_RG_16, "BayerRG16"},
      {ARV_PIXEL_FORMAT_BAYER_GR_16, "BayerGR16"},
      {ARV_PIXEL_FORMAT_BAYER_GB_16, "BayerGB16"},
      {ARV_PIXEL_FORMAT_BAYER_BG_16, "BayerBG16"},
      {ARV_PIXEL_FORMAT_RGB_8_PACKED, "RGB8"},
      {ARV_PIXEL_FORMAT_BGR_8_PACKED, "BGR8"},
  };
  for (const Entry& e : kTable) {
    if (e.format == f) return e.name;
  }
  return "";
}

double ClockSeconds(clockid_t id) {
  timespec ts{};
  ::clock_gettime(id, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

class AravisSource : public FrameSource {
 public:
  explicit AravisSource(const SourceUri& uri)
      : id_(uri.path),
        format_(uri.GetString("format", "")),
        exposure_us_(uri.GetDouble("exposure_us", 0, 1, 1e7)),
        gain_(uri.GetDouble("gain", 0, 0, 100)),
        has_gain_(uri.params.count("gain") > 0),
        fps_(uri.GetDouble("fps", 0, 0.1, 1000)),
        n_buffers_(uri.GetInt("buffers", 8, 2, 64)),
        timeout_ms_(uri.GetInt("timeout_ms", 2000, 1, 600000)),
        keep_mosaic_(KeepsMosaic(uri)) {}
  ~AravisSource() override { Close(); }

  Status Open() override {
    if (camera_ != nullptr) return Status::Ok();
    // Aravis' simulated camera ("Fake_1"), for tests without hardware.
    if (id_.rfind("Fake_", 0) == 0) arv_enable_interface("Fake");
    GError* error = nullptr;
    camera_ = arv_camera_new(id_.c_str(), &error);
    if (camera_ == nullptr) {
      const Status::Kind kind =
          error ? KindOfError(error) : Status::Kind::kNotFound;
      return Status::Error(kind, "aravis camera '" + id_ +
                                     "': " + TakeError(&error) +
                                     " (see kincal capture --list)");
    }
    Status s = Configure();
    if (!s.ok()) Close();
    return s;
  }

  Status Grab(Frame* frame) override {
    if (stream_ == nullptr) {
      return Status::Error(Status::Kind::kIoError, Describe() + ": not open");
    }
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(
        stream_, static_cast<guint64>(timeout_ms_) * 1000);
    if (buffer == nullptr) {
      return Status::Error(Status::Kind::kTimeout,
                           "aravis camera '" + id_ + "': no frame within " +
                               std::to_string(timeout_ms_) + " ms");
    }
    Status s = Convert(buffer, frame);
    arv_stream_push_buffer(stream_, buffer);
    return s;
  }

  Status Close() override {
    if (camera_ == nullptr) return Status::Ok();
    GError* error = nullptr;
    if (acquiring_) {
      arv_camera_stop_acquisition(camera_, &error);
      TakeError(&error);
      acquiring_ = false;
    }
    if (stream_ != nullptr) {
      g_object_unref(stream_);
      stream_ = nullptr;
    }
    g_object_unref(camera_);
    camera_ = nullptr;
    return Status::Ok();
  }

  std::string Describe() const override {
    std::ostringstream os;
    os << "aravis " << id_;
    if (!model_.empty()) os << " (" << model_ << ")";
    if (!format_.empty()) os << " " << format_;
    if (width_ > 0) os << " " << width_ << "x" << height_;
    if (fps_ > 0) os << " " << fps_ << " fps";
    if (exposure_us_ > 0) os << " exposure " << exposure_us_ << " us";
    if (has_gain_) os << " gain " << gain_;
    if (!mosaic_.empty()) os << ", raw mosaic";
    return os.str();
  }
  std::string mosaic() const override { return mosaic_; }
  bool IsLive() const override { return true; }
  TimeBase time_base() const override { return TimeBase::kHostMonotonic; }

 private:
  Status Fail(GError** error, const std::string& what) {
    const Status::Kind kind = KindOfError(*error);
    return Status::Error(
        kind, "aravis camera '" + id_ + "': " + what + ": " + TakeError(error));
  }

  Status Configure() {
    GError* error = nullptr;
    const char* model = arv_camera_get_model_name(camera_, &error);
    if (model != nullptr) model_ = model;
    TakeError(&error);
    if (!format_.empty()) {
      arv_camera_set_pixel_format_from_string(camera_, format_.c_str(), &error);
      if (error) return Fail(&error, "cannot set format " + format_);
    }
    arv_camera_set_acquisition_mode(camera_, ARV_ACQUISITION_MODE_CONTINUOUS,
                                    &error);
    if (error) return Fail(&error, "cannot set continuous acquisition");
    if (exposure_us_ > 0) {
      arv_camera_set_exposure_time_auto(camera_, ARV_AUTO_OFF, &error);
      TakeError(&error);  // cameras without auto exposure
      arv_camera_set_exposure_time(camera_, exposure_us_, &error);
      if (error) return Fail(&error, "cannot set exposure");
    }
    if (has_gain_) {
      arv_camera_set_gain_auto(camera_, ARV_AUTO_OFF, &error);
      TakeError(&error);
      arv_camera_set_gain(camera_, gain_, &error);
      if (error) return Fail(&error, "cannot set gain");
    }
    if (fps_ > 0) {
      arv_camera_set_frame_rate(camera_, fps_, &error);
      if (error) return Fail(&error, "cannot set frame rate");
    }
    if (arv_camera_is_gv_device(camera_)) {
      arv_camera_gv_auto_packet_size(camera_, &error);
      TakeError(&error);  // keeps the default packet size
    }
    const char* actual = arv_camera_get_pixel_format_as_string(camera_, &error);
    if (error) return Fail(&error, "cannot read the pixel format");
    format_ = actual ? actual : "";
    PixelLayout layout;
    BayerPattern bayer;
    int bits;
    if (!LayoutFromGenicamName(format_, &layout, &bayer, &bits)) {
      return Status::Error(Status::Kind::kUnsupported,
                           "aravis camera '" + id_ + "': pixel format '" +
                               format_ +
                               "' not supported; use format=Mono8, Mono16, "
                               "BayerRG8, ... in the URI");
    }
    if (keep_mosaic_ && layout != PixelLayout::kBayer8 &&
        layout != PixelLayout::kBayer16) {
      return Status::Error(Status::Kind::kUnsupported,
                           "aravis camera '" + id_ +
                               "': bayer=raw, but it "
                               "delivers " +
                               format_ +
                               "; give format=BayerRG8 (or the camera's "
                               "Bayer format) or drop bayer=raw");
    }
    mosaic_ = keep_mosaic_ ? MosaicName(bayer) : "";
    gint x = 0, y = 0;
    arv_camera_get_region(camera_, &x, &y, &width_, &height_, &error);
    TakeError(&error);
    const guint payload = arv_camera_get_payload(camera_, &error);
    if (error) return Fail(&error, "cannot read the payload size");
    stream_ = arv_camera_create_stream(camera_, nullptr, nullptr, &error);
    if (stream_ == nullptr) {
      if (error) return Fail(&error, "cannot create the stream");
      return Status::Error(Status::Kind::kIoError,
                           "aravis camera '" + id_ + "': no stream");
    }
    for (int i = 0; i < n_buffers_; ++i) {
      arv_stream_push_buffer(stream_, arv_buffer_new(payload, nullptr));
    }
    arv_camera_start_acquisition(camera_, &error);
    if (error) return Fail(&error, "cannot start acquisition");
    acquiring_ = true;
    return Status::Ok();
  }

  Status Convert(ArvBuffer* buffer, Frame* frame) {
    const ArvBufferStatus st = arv_buffer_get_status(buffer);
    if (st != ARV_BUFFER_STATUS_SUCCESS) {
      return Status::Error(Status::Kind::kIoError,
                           "aravis camera '" + id_ + "': incomplete frame " +
                               std::to_string(arv_buffer_get_frame_id(buffer)) +
                               " (buffer status " + std::to_string(int(st)) +
                               ", e.g. missing packets)");
    }
    const ArvPixelFormat pf = arv_buffer_get_image_pixel_format(buffer);
    PixelBuffer pb;
    if (!LayoutFromGenicamName(PixelFormatName(pf), &pb.layout, &pb.bayer,
                               &pb.bits)) {
      return Status::Error(
          Status::Kind::kUnsupported, "aravis camera '" + id_ +
                                          "': pixel format 0x" +
                                          [pf] {
                                            std::ostringstream os;
                                            os << std::hex << pf;
                                            return os.str();
                                          }() +
                                          " not supported");
    }
    size_t size = 0;
    pb.data = arv_buffer_get_image_data(buffer, &size);
    pb.bytes = size;
    pb.width = arv_buffer_get_image_width(buffer);
    pb.height = arv_buffer_get_image_height(buffer);
    pb.keep_mosaic = keep_mosaic_;
    Status s = ConvertToMat(pb, &frame->image);
    if (!s.ok()) {
      return Status::Error(s.kind(),
                           "aravis camera '" + id_ + "': " + s.message());
    }
    // Host receive time is CLOCK_REALTIME; move it to CLOCK_MONOTONIC so
    // frames of all live sources share one clock that never jumps.
    const double realtime_ns = double(arv_buffer_get_system_timestamp(buffer));
    const double offset =
        ClockSeconds(CLOCK_REALTIME) - ClockSeconds(CLOCK_MONOTONIC);
    frame->timestamp_s = realtime_ns * 1e-9 - offset;
    frame->sequence = static_cast<int64_t>(arv_buffer_get_frame_id(buffer));
    return Status::Ok();
  }

  std::string id_;
  std::string format_;
  double exposure_us_;
  double gain_;
  bool has_gain_;
  double fps_;
  int n_buffers_;
  int timeout_ms_;
  bool keep_mosaic_;    // bayer=raw
  std::string mosaic_;  // the kept mosaic's pattern, after Open
  std::string model_;
  gint width_ = 0;
  gint height_ = 0;
  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  bool acquiring_ = false;
};

}  // namespace

std::unique_ptr<FrameSource> MakeAravisSource(const SourceUri& uri) {
  return std::make_unique<AravisSource>(uri);
}

Status ListAravisCameras(std::vector<CameraInfo>* cameras) {
  cameras->clear();
  arv_update_device_list();
  const unsigned n = arv_get_n_devices();
  for (unsigned i = 0; i < n; ++i) {
    auto str = [](const char* s) { return std::string(s ? s : "?"); };
    CameraInfo info;
    info.uri = "aravis:" + str(arv_get_device_id(i));
    info.description = str(arv_get_device_vendor(i)) + " " +
                       str(arv_get_device_model(i)) + ", serial " +
                       str(arv_get_device_serial_nbr(i)) + " [" +
                       str(arv_get_device_protocol(i)) + "]";
    cameras->push_back(info);
  }
  return Status::Ok();
}

#else  // !KINCAL_HAVE_ARAVIS

bool HaveAravis() { return false; }

namespace {
class NoAravisSource : public FrameSource {
 public:
  explicit NoAravisSource(const SourceUri& uri) : id_(uri.path) {}
  Status Open() override { return Unsupported(); }
  Status Grab(Frame*) override { return Unsupported(); }
  Status Close() override { return Status::Ok(); }
  std::string Describe() const override { return "aravis " + id_; }
  bool IsLive() const override { return true; }
  TimeBase time_base() const override { return TimeBase::kHostMonotonic; }

 private:
  static Status Unsupported() {
    return Status::Error(Status::Kind::kUnsupported,
                         "kincal was built without Aravis");
  }
  std::string id_;
};
}  // namespace

std::unique_ptr<FrameSource> MakeAravisSource(const SourceUri& uri) {
  return std::make_unique<NoAravisSource>(uri);
}

Status ListAravisCameras(std::vector<CameraInfo>* cameras) {
  cameras->clear();
  return Status::Error(Status::Kind::kUnsupported,
                       "kincal was built without Aravis");
}

#endif  // KINCAL_HAVE_ARAVIS

}  // namespace kincal::capture
