#include "capture/recorder.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "capture/png_encode.h"
#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/session.h"
#include "data/yaml_util.h"

namespace kincal::capture {
namespace {

Status IoError(const std::string& path, const std::string& what, int err) {
  return Status::Error(Status::Kind::kIoError,
                       path + ": " + what + ": " + std::strerror(err));
}

// True when `dir` does not exist or holds no entries.
bool IsAbsentOrEmpty(const std::string& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return errno == ENOENT;
  bool empty = true;
  while (dirent* e = ::readdir(d)) {
    if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) {
      empty = false;
      break;
    }
  }
  ::closedir(d);
  return empty;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// Runs a data/ writer (which throws InputError) and returns its Status.
template <typename F>
Status Guard(F&& f) {
  try {
    f();
    return Status::Ok();
  } catch (const std::exception& e) {
    return Status::Error(Status::Kind::kIoError, e.what());
  }
}

}  // namespace

Status WriteBytes(const std::string& path, const void* data, size_t size) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return IoError(path, "cannot create", errno);
  const char* p = static_cast<const char*>(data);
  size_t left = size;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      return IoError(path, "write failed", err);
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  // close() reports delayed write errors (e.g. ENOSPC on network folders).
  if (::close(fd) != 0) return IoError(path, "write failed", errno);
  return Status::Ok();
}

Status WritePngAtomic(const std::string& path, const cv::Mat& image,
                      int compression, size_t* bytes) {
  std::vector<uint8_t> png;
  std::string error;
  if (!EncodePng(image, compression, &png, &error)) {
    return Status::Error(Status::Kind::kUnsupported,
                         path + ": cannot encode PNG: " + error);
  }
  const std::string part = path + ".part";
  Status s = WriteBytes(part, png.data(), png.size());
  if (!s.ok()) {
    ::unlink(part.c_str());
    return s;
  }
  if (::rename(part.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(part.c_str());
    return IoError(path, "cannot rename " + part, err);
  }
  if (bytes) *bytes = png.size();
  return Status::Ok();
}

Status MakeDirs(const std::string& dir) {
  if (dir.empty()) {
    return Status::Error(Status::Kind::kIoError, "empty folder name");
  }
  size_t pos = 0;
  while (pos != std::string::npos) {
    pos = dir.find('/', pos + 1);
    const std::string part = dir.substr(0, pos);
    if (part.empty()) continue;
    if (::mkdir(part.c_str(), 0755) != 0 && errno != EEXIST) {
      return IoError(part, "cannot create folder", errno);
    }
    struct stat st {};
    if (::stat(part.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
      return Status::Error(Status::Kind::kIoError,
                           part + ": exists and is not a folder");
    }
  }
  return Status::Ok();
}

SessionRecorder::~SessionRecorder() {
  if (journal_) std::fclose(journal_);
}

std::string SessionRecorder::FrameFileName(int64_t frame) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06lld.png", static_cast<long long>(frame));
  return buf;
}

std::vector<std::string> SessionRecorder::CameraNames() const {
  std::vector<std::string> names;
  for (const SessionCamera& c : info_.cameras) names.push_back(c.name);
  return names;
}

std::string SessionRecorder::ImagePath(size_t camera, int64_t frame) const {
  return dir_ + "/" + info_.cameras[camera].name + "/" + FrameFileName(frame);
}

std::string SessionRecorder::CsvHeader() const {
  std::string h = SessionFramesHeader(CameraNames(), {});
  for (const std::string& j : info_.joint_names) h += "," + CsvQuote(j);
  return h + "\n";
}

Status SessionRecorder::Open(const std::string& dir, const SessionInfo& info) {
  if (open_) {
    return Status::Error(Status::Kind::kIoError,
                         "recorder already open on " + dir_);
  }
  if (info.cameras.empty()) {
    return Status::Error(Status::Kind::kUnsupported,
                         "a recording needs at least one camera");
  }
  std::set<std::string> names = {"frame"};
  for (const SessionCamera& c : info.cameras) {
    try {
      CheckSessionCameraName(c.name, "capture");
    } catch (const InputError& e) {
      return Status::Error(Status::Kind::kUnsupported, e.what());
    }
    if (!names.insert("t_" + c.name).second) {
      return Status::Error(Status::Kind::kUnsupported,
                           "camera name '" + c.name + "' given twice");
    }
    names.insert("seq_" + c.name);
  }
  for (const std::string& j : info.joint_names) {
    if (j.empty() || !names.insert(j).second) {
      return Status::Error(
          Status::Kind::kUnsupported,
          "joint column '" + j + "' is empty or repeats another column");
    }
  }
  if (!IsAbsentOrEmpty(dir)) {
    return Status::Error(Status::Kind::kIoError,
                         dir +
                             ": exists and is not empty (kincal never "
                             "overwrites a session; choose a new folder)");
  }
  std::vector<std::string> folders = {dir};
  for (const SessionCamera& c : info.cameras)
    folders.push_back(dir + "/" + c.name);
  for (const std::string& d : folders) {
    Status s = MakeDirs(d);
    if (!s.ok()) return s;
  }
  dir_ = dir;
  info_ = info;
  started_utc_ = UtcNow();
  rows_.clear();
  frames_ = 0;
  bytes_ = 0;
  const std::string journal = dir_ + "/frames.csv.part";
  journal_ = std::fopen(journal.c_str(), "w");
  if (journal_ == nullptr) return IoError(journal, "cannot create", errno);
  if (std::fputs(CsvHeader().c_str(), journal_) < 0 ||
      std::fflush(journal_) != 0) {
    return IoError(journal, "write failed", errno);
  }
  Status s = Guard(
      [&] { WriteFileAtomic(dir_ + "/session.yaml", SessionYaml(nullptr)); });
  if (!s.ok()) return s;
  open_ = true;
  return Status::Ok();
}

Status SessionRecorder::Write(const FrameSet& set,
                              const std::vector<double>& joints) {
  Status s = CheckWrite(frames_, joints);
  if (!s.ok()) return s;
  uint64_t bytes = 0;
  s = WriteSetImages(frames_, set, &bytes);
  if (!s.ok()) return s;
  return CommitRow(set, joints, bytes);
}

Status SessionRecorder::CheckWrite(int64_t frame,
                                   const std::vector<double>& joints) const {
  if (!open_) {
    return Status::Error(Status::Kind::kIoError, "recorder not open");
  }
  if (joints.size() != info_.joint_names.size()) {
    return Status::Error(
        Status::Kind::kUnsupported,
        "frame " + std::to_string(frame) + ": " +
            std::to_string(joints.size()) + " joint values for " +
            std::to_string(info_.joint_names.size()) + " joint columns");
  }
  if (frame >= kMaxFrames) {
    return Status::Error(Status::Kind::kUnsupported,
                         "a session holds at most " +
                             std::to_string(kMaxFrames) +
                             " frames (file names must sort in order)");
  }
  return Status::Ok();
}

Status SessionRecorder::CheckSet(int64_t frame, const FrameSet& set) const {
  if (set.frames.size() == info_.cameras.size()) return Status::Ok();
  return Status::Error(Status::Kind::kUnsupported,
                       "frame " + std::to_string(frame) + ": " +
                           std::to_string(set.frames.size()) + " images for " +
                           std::to_string(info_.cameras.size()) + " cameras");
}

Status SessionRecorder::WriteSetImages(int64_t frame, const FrameSet& set,
                                       uint64_t* bytes, int compression) const {
  Status s = CheckSet(frame, set);
  if (!s.ok()) return s;
  const int level = compression >= 0 ? compression : options_.png_compression;
  uint64_t total = 0;
  for (size_t c = 0; c < info_.cameras.size(); ++c) {
    size_t image_bytes = 0;
    s = WritePngAtomic(ImagePath(c, frame), set.frames[c].image, level,
                       &image_bytes);
    if (!s.ok()) {
      RemoveSetImages(frame);  // never leave part of a set
      return s;
    }
    total += image_bytes;
  }
  *bytes = total;
  return Status::Ok();
}

void SessionRecorder::RemoveSetImages(int64_t frame) const {
  for (size_t c = 0; c < info_.cameras.size(); ++c) {
    ::unlink(ImagePath(c, frame).c_str());
  }
}

Status SessionRecorder::CommitRow(const FrameSet& set,
                                  const std::vector<double>& joints,
                                  uint64_t bytes) {
  Status s = CheckWrite(frames_, joints);
  if (s.ok()) s = CheckSet(frames_, set);
  if (!s.ok()) return s;
  // frame, t_<camera>..., seq_<camera>... (SessionFramesHeader's order).
  std::string row = std::to_string(frames_);
  for (const Frame& f : set.frames) row += "," + FormatFixed(f.timestamp_s, 6);
  for (const Frame& f : set.frames) row += "," + std::to_string(f.sequence);
  for (double v : joints) {
    row += ",";
    if (v == v) {  // NaN = no reading: empty cell
      std::ostringstream os;
      os.precision(10);
      os << v;
      row += os.str();
    }
  }
  row += "\n";
  if (std::fputs(row.c_str(), journal_) < 0 || std::fflush(journal_) != 0) {
    const int err = errno;
    RemoveSetImages(frames_);
    return IoError(dir_ + "/frames.csv.part", "write failed", err);
  }
  rows_.push_back(std::move(row));
  bytes_ += bytes;
  ++frames_;
  return Status::Ok();
}

Status SessionRecorder::SetJointColumns(
    const std::vector<std::string>& names,
    const std::vector<std::vector<double>>& values) {
  if (!info_.joint_names.empty()) {
    return Status::Error(Status::Kind::kUnsupported,
                         "the session already has joint columns");
  }
  if (values.size() != rows_.size()) {
    return Status::Error(Status::Kind::kUnsupported,
                         std::to_string(values.size()) + " joint rows for " +
                             std::to_string(rows_.size()) + " frames");
  }
  std::set<std::string> seen = {"frame"};
  for (const SessionCamera& c : info_.cameras) {
    seen.insert("t_" + c.name);
    seen.insert("seq_" + c.name);
  }
  for (const std::string& n : names) {
    if (n.empty() || !seen.insert(n).second) {
      return Status::Error(
          Status::Kind::kUnsupported,
          "joint column '" + n + "' is empty or repeats another column");
    }
  }
  for (size_t r = 0; r < rows_.size(); ++r) {
    if (values[r].size() != names.size()) {
      return Status::Error(
          Status::Kind::kUnsupported,
          "frame " + std::to_string(r) + ": wrong number of joint values");
    }
    std::string& row = rows_[r];
    row.pop_back();  // "\n"
    for (double v : values[r]) {
      row += ",";
      if (v == v) {
        std::ostringstream os;
        os.precision(10);
        os << v;
        row += os.str();
      }
    }
    row += "\n";
  }
  info_.joint_names = names;
  return Status::Ok();
}

Status SessionRecorder::Finalize(const SessionSummary& summary) {
  if (!open_) {
    return Status::Error(Status::Kind::kIoError, "recorder not open");
  }
  open_ = false;
  std::string csv = "# " + CommandLine() + "\n" + CsvHeader();
  for (const std::string& r : rows_) csv += r;
  Status s = Guard([&] { WriteFileAtomic(dir_ + "/frames.csv", csv); });
  if (s.ok()) {
    s = Guard([&] {
      WriteFileAtomic(dir_ + "/session.yaml", SessionYaml(&summary));
    });
  }
  if (journal_) {
    std::fclose(journal_);
    journal_ = nullptr;
  }
  // Keep the journal when frames.csv could not be written.
  if (s.ok()) ::unlink((dir_ + "/frames.csv.part").c_str());
  return s;
}

std::string SessionRecorder::SessionYaml(const SessionSummary* summary) const {
  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "kincal_session" << YAML::Value << 1;
  y << YAML::Key << "status" << YAML::Value
    << (summary == nullptr ? "recording"
                           : (summary->complete ? "complete" : "failed"));
  y << YAML::Key << "started_utc" << YAML::Value << started_utc_;
  y << YAML::Key << "tool" << YAML::Value << ToolVersion();
  y << YAML::Key << "command" << YAML::Value << CommandLine();
  y << YAML::Key << "frames" << YAML::Value << frames_;
  y << YAML::Key << "images" << YAML::Value << YAML::BeginMap;
  for (const SessionCamera& c : info_.cameras) {
    y << YAML::Key << c.name << YAML::Value << c.name + "/*.png";
  }
  y << YAML::Key << "format" << YAML::Value << "png";
  y << YAML::Key << "png_compression" << YAML::Value
    << options_.png_compression;
  y << YAML::EndMap;
  y << YAML::Key << "frames_csv" << YAML::Value << "frames.csv";
  y << YAML::Key << "sources" << YAML::Value << YAML::BeginMap;
  for (const SessionCamera& c : info_.cameras) {
    y << YAML::Key << c.name << YAML::Value << YAML::BeginMap;
    y << YAML::Key << "uri" << YAML::Value << c.uri;
    y << YAML::Key << "description" << YAML::Value << c.description;
    if (!c.mosaic.empty()) {
      y << YAML::Key << "mosaic" << YAML::Value << c.mosaic;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndMap;
  y << YAML::Key << "live" << YAML::Value << info_.live;
  y << YAML::Key << "time_base" << YAML::Value << info_.time_base;
  y << YAML::Key << "pairing" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "mode" << YAML::Value << info_.pairing;
  y << YAML::Key << "tolerance_s" << YAML::Value << info_.tolerance_s;
  if (summary != nullptr) {
    // Per camera: frames in no set; then the sets the writers could not
    // keep up with (dropped_pairs, the name it has had since two cameras).
    y << YAML::Key << "dropped" << YAML::Value << YAML::BeginMap;
    for (size_t c = 0; c < info_.cameras.size(); ++c) {
      y << YAML::Key << info_.cameras[c].name << YAML::Value
        << (c < summary->dropped.size() ? summary->dropped[c] : 0);
    }
    y << YAML::EndMap;
    y << YAML::Key << "dropped_pairs" << YAML::Value << summary->dropped_sets;
    y << YAML::Key << "length_mismatch" << YAML::Value
      << summary->length_mismatch;
  }
  y << YAML::EndMap;
  y << YAML::Key << "joints" << YAML::Value << YAML::Flow << info_.joint_names;
  y << YAML::Key << "settings" << YAML::Value << YAML::BeginMap;
  for (const auto& [k, v] : info_.settings) {
    y << YAML::Key << k << YAML::Value << v;
  }
  y << YAML::EndMap;
  if (summary != nullptr) {
    y << YAML::Key << "stop_reason" << YAML::Value << summary->stop_reason;
    y << YAML::Key << "seconds" << YAML::Value << summary->seconds;
  }
  y << YAML::EndMap;
  return "# " + CommandLine() + "\n" + y.c_str() + "\n";
}

}  // namespace kincal::capture
