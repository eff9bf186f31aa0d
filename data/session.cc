#include "data/session.h"

#include <algorithm>
#include <cctype>
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

// Where each column of frames.csv is: `frame`, per camera its t_ and seq_
// columns (Session::cameras order), the joint columns (file order).
struct FramesLayout {
  int frame = -1;
  std::vector<int> t, seq;
  std::vector<int> joints;
};

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.size() > prefix.size() && s.compare(0, prefix.size(), prefix) == 0;
}

// Cameras of the header in the order of their t_ columns: names with both a
// t_<name> and a seq_<name> column.
std::vector<std::string> HeaderCameras(const CsvLine& header) {
  std::set<std::string> seqs;
  for (const CsvField& f : header.fields) {
    if (StartsWith(f.text, "seq_")) seqs.insert(f.text.substr(4));
  }
  std::vector<std::string> cameras;
  for (const CsvField& f : header.fields) {
    if (StartsWith(f.text, "t_") && seqs.count(f.text.substr(2))) {
      cameras.push_back(f.text.substr(2));
    }
  }
  return cameras;
}

// The rig's cameras (when given) as the session names them: the same names,
// or a version-2 left/right session for a two-camera rig named otherwise.
std::vector<std::string> SessionCamerasFor(
    const std::vector<std::string>& in_file,
    const std::vector<std::string>& rig_names, const CsvLine& header,
    const std::string& file) {
  if (rig_names.empty()) return in_file;
  const std::vector<std::string> v2 = {"left", "right"};
  std::set<std::string> file_set(in_file.begin(), in_file.end());
  std::set<std::string> rig_set(rig_names.begin(), rig_names.end());
  if (file_set == rig_set) return rig_names;
  if (rig_names.size() == 2 && in_file.size() == 2 &&
      file_set == std::set<std::string>(v2.begin(), v2.end()) &&
      !rig_set.count("left") && !rig_set.count("right")) {
    return v2;
  }
  std::vector<std::string> missing, foreign;
  for (const std::string& n : rig_names) {
    if (!file_set.count(n)) missing.push_back(n);
  }
  for (const std::string& n : in_file) {
    if (!rig_set.count(n)) foreign.push_back(n);
  }
  std::string msg = "the session's cameras (" + Join(in_file) +
                    ") are not the rig's (" + Join(rig_names) + ")";
  if (!missing.empty()) {
    msg += "; no t_<name>, seq_<name> columns for: " + Join(missing);
  }
  if (!foreign.empty()) msg += "; not in the rig: " + Join(foreign);
  msg +=
      " (frames.csv holds t_<camera> and seq_<camera> for every camera of "
      "rig.yaml, and one image folder per camera: the session of another "
      "rig?)";
  throw InputError(file, header.line, header.end_column, msg);
}

// The header: `frame`, the cameras' columns, the joint columns (returned in
// session->joint_columns).
FramesLayout ParseFramesHeader(const CsvLine& header,
                               const SessionReadOptions& options,
                               const std::string& file, Session* session) {
  FramesLayout layout;
  std::set<std::string> seen;
  for (const CsvField& f : header.fields) {
    if (f.text.empty()) {
      throw InputError(file, header.line, f.column, "empty column name");
    }
    if (!seen.insert(f.text).second) {
      throw InputError(file, header.line, f.column,
                       "duplicate column '" + f.text + "'");
    }
  }
  const std::vector<std::string> in_file = HeaderCameras(header);
  session->cameras =
      SessionCamerasFor(in_file, options.camera_names, header, file);
  if (session->cameras.empty()) {
    throw InputError(file, header.line, header.end_column,
                     "header: expected t_<camera> and seq_<camera> columns "
                     "for every camera (e.g. "
                     "frame,t_left,t_right,seq_left,seq_right)");
  }
  layout.t.assign(session->cameras.size(), -1);
  layout.seq.assign(session->cameras.size(), -1);
  session->joint_columns.clear();
  for (size_t i = 0; i < header.fields.size(); ++i) {
    const std::string& name = header.fields[i].text;
    const int col = static_cast<int>(i);
    bool camera_column = false;
    for (size_t c = 0; c < session->cameras.size(); ++c) {
      if (name == "t_" + session->cameras[c]) layout.t[c] = col;
      if (name == "seq_" + session->cameras[c]) layout.seq[c] = col;
      camera_column = camera_column || name == "t_" + session->cameras[c] ||
                      name == "seq_" + session->cameras[c];
    }
    if (name == "frame") {
      layout.frame = col;
    } else if (!camera_column) {
      layout.joints.push_back(col);
      session->joint_columns.push_back(name);
    }
  }
  if (layout.frame < 0) {
    throw InputError(file, header.line, 1,
                     "header: expected a 'frame' column (frames.csv holds "
                     "frame, t_<camera> and seq_<camera> for every camera, "
                     "and the joint columns)");
  }
  return layout;
}

// Per robot joint, its field index; InputError unless the joint columns are
// exactly the robot's joints. Empty without joint names.
std::vector<int> MapJointColumns(const Session& session,
                                 const FramesLayout& layout,
                                 const std::vector<std::string>& joint_names,
                                 const CsvLine& header,
                                 const std::string& file) {
  const std::vector<std::string>& joint_columns = session.joint_columns;
  std::vector<int> column_of;
  if (joint_names.empty()) return column_of;
  std::vector<std::string> missing, foreign;
  for (const std::string& name : joint_names) {
    auto it = std::find(joint_columns.begin(), joint_columns.end(), name);
    if (it == joint_columns.end()) {
      missing.push_back(name);
    } else {
      column_of.push_back(layout.joints[it - joint_columns.begin()]);
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
          ") need one column each beside the cameras' t_ and seq_ columns "
          "(joint readings at each frame)";
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
void ParseTimesAndSequences(const CsvLine& line, const CsvLine& header,
                            const std::string& file, const FramesLayout& layout,
                            SessionFrame* f) {
  const size_t nc = layout.t.size();
  f->t.assign(nc, 0.0);
  f->seq.assign(nc, 0);
  for (size_t k = 0; k < nc; ++k) {
    const CsvField& c = line.fields[layout.t[k]];
    if (!c.text.empty() && !ParseFiniteDouble(c.text, &f->t[k])) {
      throw InputError(file, line.line, c.column,
                       header.fields[layout.t[k]].text +
                           ": expected a time in seconds, got '" + c.text +
                           "'");
    }
    const CsvField& s = line.fields[layout.seq[k]];
    if (!s.text.empty() && !ParseInteger(s.text, &f->seq[k])) {
      throw InputError(file, line.line, s.column,
                       header.fields[layout.seq[k]].text +
                           ": expected an integer sequence number, got '" +
                           s.text + "'");
    }
  }
}

// Joint cells: all empty (no reading) or all numbers; the robot's joints
// (column_of) go to f->q.
void ParseJointCells(const CsvLine& line, const CsvLine& header,
                     const std::string& file, const FramesLayout& layout,
                     const std::vector<int>& column_of, SessionFrame* f) {
  int empty = 0;
  for (int i : layout.joints) empty += line.fields[i].text.empty() ? 1 : 0;
  if (empty != 0 && empty != static_cast<int>(layout.joints.size())) {
    for (int i : layout.joints) {
      if (line.fields[i].text.empty()) {
        throw InputError(file, line.line, line.fields[i].column,
                         "joint '" + header.fields[i].text +
                             "' is empty but other joints of this frame "
                             "have readings (all or none)");
      }
    }
  }
  if (empty != 0) return;
  for (int i : layout.joints) {
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
                           const std::string& file, const FramesLayout& layout,
                           const std::vector<int>& column_of,
                           std::set<long long>* frames_seen) {
  const size_t ncols = header.fields.size();
  if (line.fields.size() != ncols) {
    throw InputError(file, line.line,
                     line.fields.size() < ncols ? line.end_column
                                                : line.fields[ncols].column,
                     "expected " + std::to_string(ncols) + " cells (" +
                         std::to_string(ncols - layout.joints.size()) + " + " +
                         std::to_string(layout.joints.size()) +
                         " joint columns), got " +
                         std::to_string(line.fields.size()));
  }
  SessionFrame f;
  f.line = line.line;
  long long frame = 0;
  const CsvField& cell = line.fields[layout.frame];
  if (!ParseInteger(cell.text, &frame) || frame < 0 || frame > 99999999) {
    throw InputError(
        file, line.line, cell.column,
        "frame: expected a non-negative integer, got '" + cell.text + "'");
  }
  if (!frames_seen->insert(frame).second) {
    throw InputError(file, line.line, cell.column,
                     "frame " + std::to_string(frame) + " appears twice");
  }
  f.frame = static_cast<int>(frame);
  ParseTimesAndSequences(line, header, file, layout, &f);
  ParseJointCells(line, header, file, layout, column_of, &f);
  return f;
}

void RequireJointReadings(const SessionReadOptions& options, const Session& s) {
  if (options.require_joint_readings && s.CountWithJoints() == 0) {
    throw InputError(s.frames_csv, 0, 0,
                     "no frame has joint readings (the joint cells are "
                     "empty in every row)");
  }
}

// What session.yaml says that the readers use.
struct SessionYaml {
  std::string status;
  // sources.<folder>.mosaic: the pattern of raw mosaics, by image folder.
  std::map<std::string, std::string> mosaics;
};

// sources.<name>.mosaic where given (RGGB, GRBG, GBRG or BGGR).
std::map<std::string, std::string> ReadSourceMosaics(const YamlReader& reader,
                                                     const YAML::Node& root) {
  std::map<std::string, std::string> out;
  const YAML::Node sources = root["sources"];
  if (!sources || !sources.IsMap()) return out;
  for (const auto& entry : sources) {
    const YAML::Node source = entry.second;
    if (!source.IsMap() || !source["mosaic"]) continue;
    const YAML::Node node = source["mosaic"];
    const std::string m = reader.String(node, "mosaic");
    if (!IsMosaicPattern(m)) {
      reader.Fail(node, "sources." + entry.first.as<std::string>() +
                            ".mosaic: expected RGGB, GRBG, GBRG or BGGR (the "
                            "raw mosaic's top-left 2x2 cell), got '" +
                            m + "'");
    }
    out[entry.first.as<std::string>()] = m;
  }
  return out;
}

// session.yaml: version, status and the sources' raw mosaics.
SessionYaml ReadSessionYaml(const std::string& yaml_path) {
  std::error_code ec;
  if (!std::filesystem::exists(yaml_path, ec)) {
    throw InputError(yaml_path +
                     ": missing (a recorded session has "
                     "session.yaml with kincal_session: 1 and "
                     "status)");
  }
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
  SessionYaml out;
  out.status = reader.String(status, "status");
  if (out.status != "complete" && out.status != "failed" &&
      out.status != "recording") {
    reader.Fail(status,
                "status: expected complete, failed or recording, "
                "got '" +
                    out.status + "'");
  }
  out.mosaics = ReadSourceMosaics(reader, root);
  return out;
}

using ImageIndex = std::map<std::string, std::string>;

// Images named otherwise than by frame number (e.g. frame numbers from 1
// but images from 000000): when no row finds an image by its number, and
// every camera folder holds the same names, one per row, they pair in
// sorted order. True when it paired them.
bool PairImagesInOrder(const std::vector<ImageIndex>& images, Session* s) {
  for (const SessionFrame& f : s->frames) {
    for (const ImageIndex& im : images) {
      if (FindImage(im, f.frame)) return false;
    }
  }
  if (s->frames.empty()) return false;
  for (const ImageIndex& im : images) {
    if (im.size() != s->frames.size()) return false;
    auto a = images[0].begin();
    for (auto b = im.begin(); b != im.end(); ++a, ++b) {
      if (a->first != b->first) return false;
    }
  }
  std::vector<ImageIndex::const_iterator> it;
  for (const ImageIndex& im : images) it.push_back(im.begin());
  for (SessionFrame& f : s->frames) {
    f.images.clear();
    for (auto& i : it) f.images.push_back((i++)->second);
  }
  return true;
}

// Every row's image in every camera folder, by frame number.
void PairImagesByNumber(const std::vector<ImageIndex>& images, bool partial,
                        Session* s) {
  const size_t nc = images.size();
  auto complete = [&](const SessionFrame& f) {
    for (const ImageIndex& im : images) {
      if (!FindImage(im, f.frame)) return false;
    }
    return true;
  };
  // Last row with every image (an unfinished session stops there).
  int last_complete = -1;
  for (size_t i = 0; i < s->frames.size(); ++i) {
    if (complete(s->frames[i])) last_complete = static_cast<int>(i);
  }
  if (partial) {
    s->dropped_tail = static_cast<int>(s->frames.size()) - 1 - last_complete;
    s->frames.resize(last_complete + 1);
  }
  std::vector<std::set<std::string>> used(nc);
  for (SessionFrame& f : s->frames) {
    f.images.clear();
    for (size_t k = 0; k < nc; ++k) {
      const std::string* path = FindImage(images[k], f.frame);
      if (path == nullptr) {
        throw InputError(s->frames_csv, f.line, 1,
                         "frame " + std::to_string(f.frame) + " has no " +
                             s->folders[k] + " image (expected " + s->dir +
                             "/" + s->folders[k] + "/" + FrameStem(f.frame) +
                             ".png): every frame has one image per camera");
      }
      used[k].insert(*path);
      f.images.push_back(*path);
    }
  }
  if (partial) return;
  for (size_t k = 0; k < nc; ++k) {
    for (const auto& [stem, path] : images[k]) {
      if (!used[k].count(path)) {
        throw InputError(path + ": image without a row in " + s->frames_csv +
                         " (every frame has one row; images without a row "
                         "are bad input)");
      }
    }
  }
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
                     "'frame,t_<camera>...,seq_<camera>...[,<joints>]' "
                     "(e.g. frame,t_left,t_right,seq_left,seq_right)");
  }
  const CsvLine& header = lines[0];
  const FramesLayout layout = ParseFramesHeader(header, options, file, session);
  const std::vector<int> column_of =
      MapJointColumns(*session, layout, options.joint_names, header, file);
  session->frames.clear();
  std::set<long long> frames_seen;
  for (size_t li = 1; li < lines.size(); ++li) {
    session->frames.push_back(ParseFrameRow(lines[li], header, file, layout,
                                            column_of, &frames_seen));
  }
}

Session ReadSession(const std::string& dir_in,
                    const SessionReadOptions& options) {
  std::string dir = dir_in;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    throw InputError(dir +
                     ": not a session folder (expected a folder with one "
                     "image folder per camera, frames.csv and session.yaml)");
  }
  Session s;
  s.dir = dir;
  const SessionYaml yaml = ReadSessionYaml(dir + "/session.yaml");
  s.status = yaml.status;
  const bool partial = s.status != "complete";
  // frames.csv (or the journal of an unfinished session).
  s.frames_csv = dir + "/frames.csv";
  if (!std::filesystem::exists(s.frames_csv, ec)) {
    const std::string journal = dir + "/frames.csv.part";
    if (partial && std::filesystem::exists(journal, ec)) {
      s.frames_csv = journal;
    } else {
      throw InputError(s.frames_csv +
                       ": missing (frame, t_<camera>, seq_<camera> for every "
                       "camera[, <joints>] per frame)");
    }
  }
  ParseSessionFramesCsv(ReadFile(s.frames_csv), s.frames_csv, options, partial,
                        &s);
  // A v2 left/right session read for a rig named otherwise keeps its
  // folders' names; the cameras take the rig's.
  s.folders = s.cameras;
  if (!options.camera_names.empty()) s.cameras = options.camera_names;
  for (const std::string& folder : s.folders) {
    const auto m = yaml.mosaics.find(folder);
    s.mosaics.push_back(m == yaml.mosaics.end() ? "" : m->second);
  }
  std::vector<ImageIndex> images;
  for (const std::string& name : s.folders) {
    const std::string folder = dir + "/" + name;
    if (!std::filesystem::is_directory(folder, ec)) {
      throw InputError(folder + ": missing image folder of camera '" + name +
                       "' (a session has one folder per camera, named as in "
                       "rig.yaml and in frames.csv's t_" +
                       name + " column, with one image per frame)");
    }
    images.push_back(ListImages(folder));
  }
  if (!PairImagesInOrder(images, &s)) PairImagesByNumber(images, partial, &s);
  RequireJointReadings(options, s);
  return s;
}

bool IsMosaicPattern(const std::string& name) {
  return name == "RGGB" || name == "GRBG" || name == "GBRG" || name == "BGGR";
}

std::string SessionFramesHeader(const std::vector<std::string>& cameras,
                                const std::vector<std::string>& joints) {
  std::string h = "frame";
  for (const std::string& c : cameras) h += ",t_" + c;
  for (const std::string& c : cameras) h += ",seq_" + c;
  for (const std::string& j : joints) h += "," + j;
  return h;
}

void CheckSessionCameraName(const std::string& name, const std::string& what) {
  bool ok = !name.empty() && name != "." && name != "..";
  for (char c : name) {
    ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
                c == '-' || c == '.');
  }
  if (!ok) {
    throw InputError(what + ": camera name '" + name +
                     "' cannot name a session's image folder and its "
                     "frames.csv columns (t_<name>, seq_<name>): use "
                     "letters, digits, '_', '-' and '.' only");
  }
}

}  // namespace kincal
