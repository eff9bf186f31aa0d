#include "data/session.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "data/atomic_file.h"
#include "data/csv.h"
#include "data/error.h"
#include "data/yaml_util.h"

namespace kincal {

int Session::CountWithJoints() const {
  int n = 0;
  for (const SessionFrame& f : frames) n += f.HasJoints() ? 1 : 0;
  return n;
}

namespace {

const char* const kFixedColumns[] = {"frame", "t_left", "t_right", "seq_left",
                                     "seq_right"};

std::string Join(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

bool ParseInteger(const std::string& text, long long* value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (errno != 0 || end == nullptr || *end != '\0') return false;
  *value = v;
  return true;
}

// stem -> path of the regular files in `folder`.
std::map<std::string, std::string> ListImages(const std::string& folder) {
  std::map<std::string, std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
    if (!e.is_regular_file()) continue;
    const std::filesystem::path p = e.path();
    const std::string ext = p.extension().string();
    if (ext == ".part" || ext == ".tmp") continue;  // unfinished writes
    out[p.stem().string()] = p.string();
  }
  if (ec)
    throw InputError(folder + ": cannot list the folder: " + ec.message());
  return out;
}

std::string FrameStem(int frame) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06d", frame);
  return buf;
}

const std::string* FindImage(const std::map<std::string, std::string>& images,
                             int frame) {
  auto it = images.find(FrameStem(frame));
  if (it == images.end()) it = images.find(std::to_string(frame));
  return it == images.end() ? nullptr : &it->second;
}

constexpr int kFixed = 5;  // frame,t_left,t_right,seq_left,seq_right

// The header: the five fixed columns, then the joint columns (returned).
std::vector<std::string> ParseFramesHeader(const CsvLine& header,
                                           const std::string& file) {
  for (int i = 0; i < kFixed; ++i) {
    const int column = i < static_cast<int>(header.fields.size())
                           ? header.fields[i].column
                           : header.end_column;
    if (i >= static_cast<int>(header.fields.size()) ||
        header.fields[i].text != kFixedColumns[i]) {
      throw InputError(
          file, header.line, column,
          std::string("header: expected column ") + std::to_string(i + 1) +
              " to be '" + kFixedColumns[i] +
              "' (frames.csv starts frame,t_left,t_right,seq_left,seq_right)" +
              (i < static_cast<int>(header.fields.size())
                   ? ", got '" + header.fields[i].text + "'"
                   : ""));
    }
  }
  std::vector<std::string> joint_columns;
  std::set<std::string> seen;
  for (size_t i = kFixed; i < header.fields.size(); ++i) {
    const CsvField& f = header.fields[i];
    if (f.text.empty()) {
      throw InputError(file, header.line, f.column, "empty column name");
    }
    if (!seen.insert(f.text).second) {
      throw InputError(file, header.line, f.column,
                       "duplicate column '" + f.text + "'");
    }
    joint_columns.push_back(f.text);
  }
  return joint_columns;
}

// Per robot joint, its field index; InputError unless the joint columns are
// exactly the robot's joints. Empty without joint names.
std::vector<int> MapJointColumns(const std::vector<std::string>& joint_columns,
                                 const std::vector<std::string>& joint_names,
                                 const CsvLine& header,
                                 const std::string& file) {
  std::vector<int> column_of;
  if (joint_names.empty()) return column_of;
  std::vector<std::string> missing, foreign;
  for (const std::string& name : joint_names) {
    auto it = std::find(joint_columns.begin(), joint_columns.end(), name);
    if (it == joint_columns.end()) {
      missing.push_back(name);
    } else {
      column_of.push_back(kFixed +
                          static_cast<int>(it - joint_columns.begin()));
    }
  }
  for (const std::string& c : joint_columns) {
    if (std::find(joint_names.begin(), joint_names.end(), c) ==
        joint_names.end()) {
      foreign.push_back(c);
    }
  }
  if (missing.empty() && foreign.empty()) return column_of;
  std::string msg;
  if (joint_columns.empty()) {
    msg = "no joint columns: the robot's joints (" + Join(joint_names) +
          ") need one column each after seq_right (joint readings at "
          "each frame)";
  } else {
    msg = "joint columns (" + Join(joint_columns) +
          ") do not match the robot's joints (" + Join(joint_names) + ")";
    if (!missing.empty()) msg += "; missing: " + Join(missing);
    if (!foreign.empty()) {
      msg += "; not joints of this robot: " + Join(foreign) +
             " (a session of another robot?)";
    }
  }
  throw InputError(file, header.line, header.end_column, msg);
}

// Times and sequence numbers may be empty (unknown); anything else in them
// must be a number.
void ParseTimesAndSequences(const CsvLine& line, const std::string& file,
                            SessionFrame* f) {
  double* times[2] = {&f->t_left, &f->t_right};
  for (int k = 0; k < 2; ++k) {
    const CsvField& c = line.fields[1 + k];
    if (c.text.empty()) continue;
    if (!ParseFiniteDouble(c.text, times[k])) {
      throw InputError(file, line.line, c.column,
                       std::string(kFixedColumns[1 + k]) +
                           ": expected a time in seconds, got '" + c.text +
                           "'");
    }
  }
  long long* seqs[2] = {&f->seq_left, &f->seq_right};
  for (int k = 0; k < 2; ++k) {
    const CsvField& c = line.fields[3 + k];
    if (c.text.empty()) continue;
    if (!ParseInteger(c.text, seqs[k])) {
      throw InputError(file, line.line, c.column,
                       std::string(kFixedColumns[3 + k]) +
                           ": expected an integer sequence number, got '" +
                           c.text + "'");
    }
  }
}

// Joint cells: all empty (no reading) or all numbers; the robot's joints
// (column_of) go to f->q.
void ParseJointCells(const CsvLine& line, const CsvLine& header,
                     const std::string& file, const std::vector<int>& column_of,
                     SessionFrame* f) {
  const size_t ncols = header.fields.size();
  int empty = 0;
  for (size_t i = kFixed; i < ncols; ++i) {
    empty += line.fields[i].text.empty() ? 1 : 0;
  }
  if (empty != 0 && empty != static_cast<int>(ncols - kFixed)) {
    for (size_t i = kFixed; i < ncols; ++i) {
      if (line.fields[i].text.empty()) {
        throw InputError(file, line.line, line.fields[i].column,
                         "joint '" + header.fields[i].text +
                             "' is empty but other joints of this frame "
                             "have readings (all or none)");
      }
    }
  }
  if (empty != 0) return;
  for (size_t i = kFixed; i < ncols; ++i) {
    double v = 0;
    if (!ParseFiniteDouble(line.fields[i].text, &v)) {
      throw InputError(file, line.line, line.fields[i].column,
                       "joint '" + header.fields[i].text +
                           "': expected a finite number (mm or deg), "
                           "got '" +
                           line.fields[i].text + "'");
    }
  }
  for (int c : column_of) {
    double v = 0;
    ParseFiniteDouble(line.fields[c].text, &v);
    f->q.push_back(v);
  }
}

// One frame row; `frames_seen` collects the frame numbers so far.
SessionFrame ParseFrameRow(const CsvLine& line, const CsvLine& header,
                           const std::string& file,
                           const std::vector<int>& column_of,
                           std::set<long long>* frames_seen) {
  const size_t ncols = header.fields.size();
  if (line.fields.size() != ncols) {
    throw InputError(
        file, line.line,
        line.fields.size() < ncols ? line.end_column
                                   : line.fields[ncols].column,
        "expected " + std::to_string(ncols) + " cells (" +
            std::to_string(kFixed) + " + " + std::to_string(ncols - kFixed) +
            " joint columns), got " + std::to_string(line.fields.size()));
  }
  SessionFrame f;
  f.line = line.line;
  long long frame = 0;
  if (!ParseInteger(line.fields[0].text, &frame) || frame < 0 ||
      frame > 99999999) {
    throw InputError(file, line.line, line.fields[0].column,
                     "frame: expected a non-negative integer, got '" +
                         line.fields[0].text + "'");
  }
  if (!frames_seen->insert(frame).second) {
    throw InputError(file, line.line, line.fields[0].column,
                     "frame " + std::to_string(frame) + " appears twice");
  }
  f.frame = static_cast<int>(frame);
  ParseTimesAndSequences(line, file, &f);
  ParseJointCells(line, header, file, column_of, &f);
  return f;
}

}  // namespace

void ParseSessionFramesCsv(const std::string& text_in, const std::string& file,
                           const SessionReadOptions& options, bool partial,
                           Session* session) {
  std::string text = text_in;
  if (partial && !text.empty() && text.back() != '\n') {
    // An unfinished session may end in the middle of a row.
    const size_t nl = text.find_last_of('\n');
    text = nl == std::string::npos ? std::string() : text.substr(0, nl + 1);
  }
  const std::vector<CsvLine> lines = TokenizeCsv(text, file);
  if (lines.empty()) {
    throw InputError(file, 0, 0,
                     "empty file: expected a header line "
                     "'frame,t_left,t_right,seq_left,seq_right[,<joints>]'");
  }
  const CsvLine& header = lines[0];
  session->joint_columns = ParseFramesHeader(header, file);
  const std::vector<int> column_of = MapJointColumns(
      session->joint_columns, options.joint_names, header, file);
  session->frames.clear();
  std::set<long long> frames_seen;
  for (size_t li = 1; li < lines.size(); ++li) {
    session->frames.push_back(
        ParseFrameRow(lines[li], header, file, column_of, &frames_seen));
  }
}

Session ReadSession(const std::string& dir_in,
                    const SessionReadOptions& options) {
  std::string dir = dir_in;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    throw InputError(dir +
                     ": not a session folder (expected a folder with "
                     "left/, right/, frames.csv and session.yaml)");
  }
  Session s;
  s.dir = dir;
  // session.yaml: version and status.
  const std::string yaml_path = dir + "/session.yaml";
  if (!std::filesystem::exists(yaml_path, ec)) {
    throw InputError(yaml_path +
                     ": missing (a recorded session has "
                     "session.yaml with kincal_session: 1 and "
                     "status)");
  }
  {
    const YamlReader reader(yaml_path);
    const YAML::Node root = reader.Load(ReadFile(yaml_path));
    reader.ExpectMap(root, "session.yaml");
    const YAML::Node version =
        reader.Required(root, "kincal_session", "session.yaml");
    if (reader.Integer(version, "kincal_session") != 1) {
      reader.Fail(version,
                  "kincal_session: expected 1 (the version this "
                  "kincal reads)");
    }
    const YAML::Node status = reader.Required(root, "status", "session.yaml");
    s.status = reader.String(status, "status");
    if (s.status != "complete" && s.status != "failed" &&
        s.status != "recording") {
      reader.Fail(status,
                  "status: expected complete, failed or recording, "
                  "got '" +
                      s.status + "'");
    }
  }
  const bool partial = s.status != "complete";
  // frames.csv (or the journal of an unfinished session).
  s.frames_csv = dir + "/frames.csv";
  if (!std::filesystem::exists(s.frames_csv, ec)) {
    const std::string journal = dir + "/frames.csv.part";
    if (partial && std::filesystem::exists(journal, ec)) {
      s.frames_csv = journal;
    } else {
      throw InputError(s.frames_csv +
                       ": missing (frame,t_left,t_right,seq_left,seq_right"
                       "[,<joints>] per stereo pair)");
    }
  }
  ParseSessionFramesCsv(ReadFile(s.frames_csv), s.frames_csv, options, partial,
                        &s);
  // Images, paired by name.
  std::map<std::string, std::string> images[2];
  const char* sides[2] = {"left", "right"};
  for (int k = 0; k < 2; ++k) {
    const std::string folder = dir + "/" + sides[k];
    if (!std::filesystem::is_directory(folder, ec)) {
      throw InputError(folder +
                       ": missing image folder (a session has "
                       "left/ and right/ with one image per frame)");
    }
    images[k] = ListImages(folder);
  }
  // Images named otherwise than by frame number (e.g. frame numbers from 1
  // but images from 000000): when no row finds an image by its number, and
  // left/ and right/ hold the same names, one per row, they pair in sorted
  // order.
  bool any = false;
  for (const SessionFrame& f : s.frames) {
    any = any || FindImage(images[0], f.frame) || FindImage(images[1], f.frame);
  }
  bool by_order = false;
  if (!any && !s.frames.empty() && images[0].size() == s.frames.size() &&
      images[1].size() == s.frames.size()) {
    by_order = true;
    for (auto a = images[0].begin(), b = images[1].begin();
         a != images[0].end(); ++a, ++b) {
      by_order = by_order && a->first == b->first;
    }
  }
  if (by_order) {
    auto a = images[0].begin(), b = images[1].begin();
    for (SessionFrame& f : s.frames) {
      f.left_image = (a++)->second;
      f.right_image = (b++)->second;
    }
    if (options.require_joint_readings && s.CountWithJoints() == 0) {
      throw InputError(s.frames_csv, 0, 0,
                       "no frame has joint readings (the joint cells are "
                       "empty in every row)");
    }
    return s;
  }
  // Last row with both images (an unfinished session stops there).
  int last_complete = -1;
  for (size_t i = 0; i < s.frames.size(); ++i) {
    if (FindImage(images[0], s.frames[i].frame) &&
        FindImage(images[1], s.frames[i].frame)) {
      last_complete = static_cast<int>(i);
    }
  }
  if (partial) {
    s.dropped_tail = static_cast<int>(s.frames.size()) - 1 - last_complete;
    s.frames.resize(last_complete + 1);
  }
  std::set<std::string> used[2];
  for (SessionFrame& f : s.frames) {
    const std::string* paths[2] = {FindImage(images[0], f.frame),
                                   FindImage(images[1], f.frame)};
    for (int k = 0; k < 2; ++k) {
      if (paths[k] == nullptr) {
        throw InputError(s.frames_csv, f.line, 1,
                         "frame " + std::to_string(f.frame) + " has no " +
                             sides[k] + " image (expected " + dir + "/" +
                             sides[k] + "/" + FrameStem(f.frame) +
                             ".png): frames must come in pairs");
      }
      used[k].insert(*paths[k]);
    }
    f.left_image = *paths[0];
    f.right_image = *paths[1];
  }
  if (!partial) {
    for (int k = 0; k < 2; ++k) {
      for (const auto& [stem, path] : images[k]) {
        if (!used[k].count(path)) {
          throw InputError(path + ": image without a row in " + s.frames_csv +
                           " (every stereo pair has one row; frames without "
                           "pairs are bad input)");
        }
      }
    }
  }
  if (options.require_joint_readings && s.CountWithJoints() == 0) {
    throw InputError(s.frames_csv, 0, 0,
                     "no frame has joint readings (the joint cells are "
                     "empty in every row)");
  }
  return s;
}

}  // namespace kincal
