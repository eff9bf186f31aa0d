#ifndef KINCAL_DATA_SESSION_H_
#define KINCAL_DATA_SESSION_H_

// Reader of a recorded session folder (../shared/spec/formats.md v3,
// "Recorded session with N cameras"), as `kincal capture` and `kincal
// simulate --render` write it:
//
//   SESSION/
//     <camera>/000000.png, ...  one image folder per camera, named as in
//                               rig.yaml (a stereo rig named left/right is
//                               version 2's left/ and right/); lossless
//                               images, any extension, paired by name
//     frames.csv                frame, t_<camera> and seq_<camera> for every
//                               camera, [<joint columns>], in any order;
//                               '#' lines are comments
//     session.yaml              kincal_session: 1, status: complete |
//                               failed | recording, ... (other keys free;
//                               sources.<camera>.mosaic: RGGB | GRBG |
//                               GBRG | BGGR when its images are a colour
//                               sensor's raw mosaic)
//
// Columns are found by name. A camera is a name with both a t_<name> and a
// seq_<name> column; every other column but `frame` is a joint column.
// Frames pair by name: frame f's images are <camera>/<f as %06d>.<ext> (a
// stem equal to the plain number is accepted too; when no row finds its
// images by number and every camera folder holds the same names, one per
// row, rows and sorted names pair in order). Empty t_/seq_ cells mean
// unknown (0). A session whose status is `recording` or `failed` is read up
// to its last frame with every camera's image: frames.csv.part is used when
// frames.csv is absent, a truncated last line is ignored, and trailing rows
// without every image are dropped (counted in `dropped_tail`). In a
// `complete` session every row needs every camera's image.
//
// Images are located, not decoded (data/ has no image library): a caller
// that decodes them reports an unreadable image as InputError naming it.

#include <string>
#include <vector>

namespace kincal {

// Whether `name` names a raw mosaic's pattern as session.yaml records it
// (sources.<camera>.mosaic): RGGB, GRBG, GBRG or BGGR, the top-left 2x2
// cell row by row.
bool IsMosaicPattern(const std::string& name);

struct SessionFrame {
  int frame = 0;  // the `frame` column
  // Per camera, in Session::cameras order: time (s; 0 = unknown), the
  // camera's sequence number, and the image's full path.
  std::vector<double> t;
  std::vector<long long> seq;
  std::vector<std::string> images;
  // Joint readings in the order of ReadSession's `joint_names` (interface
  // units: mm | deg); empty when the row's joint cells are empty.
  std::vector<double> q;
  bool HasJoints() const { return !q.empty(); }
  int line = 0;  // line in frames.csv (1-based), for messages
};

struct Session {
  std::string dir;
  std::string status;      // complete | failed | recording
  std::string frames_csv;  // the file the rows came from
  // Camera names: the rig's order when SessionReadOptions::camera_names is
  // given, else the order of their t_ columns in frames.csv. `folders` are
  // the image folders' names (equal to `cameras`, except a version-2
  // left/right session read for a two-camera rig named otherwise).
  std::vector<std::string> cameras;
  std::vector<std::string> folders;
  // Per camera (cameras order): the raw mosaic pattern its images hold
  // (session.yaml sources.<folder>.mosaic), empty for gray or colour.
  std::vector<std::string> mosaics;
  std::vector<std::string> joint_columns;  // as in frames.csv, file order
  std::vector<SessionFrame> frames;        // in file order
  int dropped_tail = 0;  // incomplete trailing rows of an unfinished session

  int CountWithJoints() const;
};

struct SessionReadOptions {
  // When not empty (a robot's joint names, in chain order): frames.csv must
  // have exactly these joint columns (any order); SessionFrame::q follows
  // this order. A missing column, or columns naming other joints (a session
  // of another robot), is InputError.
  std::vector<std::string> joint_names;
  // When true (with joint_names), a session without any row holding joint
  // readings is InputError.
  bool require_joint_readings = false;
  // When not empty (the rig's camera names, in rig order): the session must
  // hold exactly these cameras (any column order), and the per-camera
  // vectors follow this order. A version-2 session (left, right) read for a
  // two-camera rig with other names pairs left with the rig's first camera.
  std::vector<std::string> camera_names;
};

// Reads the session folder `dir`. Strict: every problem is InputError with
// file:line:column and what was expected.
Session ReadSession(const std::string& dir,
                    const SessionReadOptions& options = {});

// Parses frames.csv text (exposed for tests): fills cameras, frames
// (without image paths), joint_columns; `partial` = the session is unfinished,
// so a last line without a newline is ignored.
void ParseSessionFramesCsv(const std::string& text, const std::string& file,
                           const SessionReadOptions& options, bool partial,
                           Session* session);

// Writers of sessions (capture, simulate --render): the frames.csv header
// `frame,t_<c1>,...,t_<cN>,seq_<c1>,...,seq_<cN>[,<joints>]` (version 2's
// `frame,t_left,t_right,seq_left,seq_right` for a left/right rig).
std::string SessionFramesHeader(const std::vector<std::string>& cameras,
                                const std::vector<std::string>& joints);
// InputError unless `name` can name a session's image folder and its
// frames.csv columns: not empty, letters, digits, '_', '-', '.' only, not
// "." or "..". `what` says where the name came from.
void CheckSessionCameraName(const std::string& name, const std::string& what);

}  // namespace kincal

#endif  // KINCAL_DATA_SESSION_H_
