#ifndef KINCAL_CAPTURE_RECORDER_H_
#define KINCAL_CAPTURE_RECORDER_H_

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "capture/frame_grabber.h"

namespace kincal::capture {

// One camera of a session.
struct SessionCamera {
  // As in rig.yaml: the camera's image folder and frames.csv columns
  // (t_<name>, seq_<name>; data/session.h).
  std::string name;
  std::string uri;          // the source (capture/frame_source.h)
  std::string description;  // FrameSource::Describe()
  // FrameSource::mosaic(): the images are raw mosaics of this pattern
  // (session.yaml `sources.<name>.mosaic`); empty for gray or colour.
  std::string mosaic;
};

// What session.yaml records about how a session was made.
struct SessionInfo {
  // 1..N cameras in rig order; FrameSet::frames follows this order.
  std::vector<SessionCamera> cameras;
  bool live = false;
  std::string pairing;  // "lockstep" / "timestamp"
  double tolerance_s = 0;
  std::string time_base;  // "host_monotonic" / "media"
  // Extra frames.csv columns (robot joint readings), in order; each Write
  // passes one value per name.
  std::vector<std::string> joint_names;
  // Free-form settings recorded as given (e.g. "frames": "200").
  std::map<std::string, std::string> settings;
};

// How a session ended, recorded by Finalize.
struct SessionSummary {
  std::string stop_reason;  // "frames", "seconds", "end_of_stream", ...
  bool complete = true;     // false after a failure
  // Per camera (SessionInfo::cameras order): frames left out of every set.
  std::vector<int64_t> dropped;
  int64_t dropped_sets = 0;  // queue full: disk/encoder slower than cameras
  bool length_mismatch = false;
  double seconds = 0;  // wall time of the recording
};

// Writes a session folder (../shared/spec/formats.md v3, "Recorded session
// with N cameras") that `kincal track --session` and the bundle read:
//
//   DIR/<camera>/000000.png, 000001.png, ...  one folder per camera, named
//                                             as in rig.yaml; lossless PNG,
//                                             the same names in every folder
//   DIR/frames.csv     frame,t_<c1>,...,t_<cN>,seq_<c1>,...,seq_<cN>
//                      [,joint columns] (a left/right rig: version 2's
//                      frame,t_left,t_right,seq_left,seq_right)
//   DIR/session.yaml   sources, settings, command line, start time, how it
//                      ended
//
// Images are written as they come (each to a ".part" file renamed when
// complete, so no truncated PNG is ever matched by left/*.png); rows go to
// frames.csv.part as they come, and Finalize writes frames.csv and
// session.yaml atomically. Every failure (disk full, folder removed) is a
// Status; after a failed Write no image of the set is on disk.
class SessionRecorder {
 public:
  struct Options {
    int png_compression = 1;  // 0..9: zlib level, all lossless; 1 is fastest
  };

  SessionRecorder() = default;
  explicit SessionRecorder(Options options) : options_(options) {}
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  // Creates DIR (and parents), one folder per camera, and a first
  // session.yaml (status: recording). DIR must not exist or be empty;
  // kUnsupported without a camera, or for a camera name that cannot name a
  // folder (data/session.h) or is given twice.
  Status Open(const std::string& dir, const SessionInfo& info);
  // Writes one set (one frame per camera, in SessionInfo::cameras order) as
  // frame frames(); `joints` has one value per SessionInfo::joint_names
  // entry (kUnsupported otherwise); NaN = no reading (an empty cell).
  Status Write(const FrameSet& set, const std::vector<double>& joints = {});

  // Write in two steps, for writer threads (capture/async_recorder.h):
  // WriteSetImages encodes and writes the images of frame `frame`
  // (thread-safe, const: touches only those files; on failure none is left
  // on disk); CommitRow then appends the row of frame frames() to the
  // journal, whose images must be on disk (one thread, frame order).
  Status CheckWrite(int64_t frame, const std::vector<double>& joints) const;
  // kUnsupported unless `set` holds one frame per camera.
  Status CheckSet(int64_t frame, const FrameSet& set) const;
  // `compression` overrides Options::png_compression when >= 0.
  Status WriteSetImages(int64_t frame, const FrameSet& set, uint64_t* bytes,
                        int compression = -1) const;
  Status CommitRow(const FrameSet& set, const std::vector<double>& joints,
                   uint64_t bytes);
  // Joint readings merged after recording (capture --joints): adds the
  // columns `names` with one row of values per recorded frame (NaN = no
  // reading) to the frames.csv that Finalize writes. Only for a session
  // opened without joint columns.
  Status SetJointColumns(const std::vector<std::string>& names,
                         const std::vector<std::vector<double>>& values);
  // Adds or replaces a `settings` entry of session.yaml.
  void SetSetting(const std::string& key, const std::string& value) {
    info_.settings[key] = value;
  }
  // Removes frame `frame`'s images (written but never committed).
  void RemoveSetImages(int64_t frame) const;
  // Writes frames.csv and session.yaml (atomically) and removes the journal.
  Status Finalize(const SessionSummary& summary);

  int64_t frames() const { return frames_; }
  uint64_t bytes_written() const { return bytes_; }
  const std::string& dir() const { return dir_; }

  // "000042.png"
  static std::string FrameFileName(int64_t frame);
  // The largest frame count whose names still sort in numeric order.
  static constexpr int64_t kMaxFrames = 1000000;

 private:
  std::string SessionYaml(const SessionSummary* summary) const;
  std::string CsvHeader() const;
  std::vector<std::string> CameraNames() const;
  // DIR/<camera>/<frame>.png
  std::string ImagePath(size_t camera, int64_t frame) const;

  Options options_;
  std::string dir_;
  SessionInfo info_;
  std::string started_utc_;
  std::vector<std::string> rows_;
  int64_t frames_ = 0;
  uint64_t bytes_ = 0;
  bool open_ = false;
  std::FILE* journal_ = nullptr;  // frames.csv.part, one row per Write
};

// Writes `size` bytes to `path` (created or truncated), reporting any
// failure (ENOSPC, EIO, EACCES, ...) as kIoError with the OS message.
Status WriteBytes(const std::string& path, const void* data, size_t size);
// Encodes `image` as PNG (lossless) and writes it to path + ".part", then
// renames it to `path`.
Status WritePngAtomic(const std::string& path, const cv::Mat& image,
                      int compression, size_t* bytes = nullptr);
// mkdir -p; kIoError naming the part that could not be made.
Status MakeDirs(const std::string& dir);

}  // namespace kincal::capture

#endif  // KINCAL_CAPTURE_RECORDER_H_
