#ifndef KINCAL_DATA_SESSION_H_
#define KINCAL_DATA_SESSION_H_

// Reader of a recorded session folder (../shared/spec/formats.md v2,
// "Recorded session"), as `kincal capture` and `kincal simulate --render`
// write it:
//
//   SESSION/
//     left/000000.png, ...   lossless images (any extension; paired by name)
//     right/000000.png, ...  same names
//     frames.csv             frame,t_left,t_right,seq_left,seq_right
//                            [,<joint columns>]; '#' lines are comments
//     session.yaml           kincal_session: 1, status: complete | failed |
//                            recording, ... (other keys are free-form)
//
// Frames pair by name: frame f's images are left/<f as %06d>.<ext> and
// right/<same name> (a stem equal to the plain number is accepted too; when
// no row finds its images by number and left/ and right/ hold the same
// names, one pair per row, rows and sorted names pair in order). Empty
// t_left/t_right/seq cells mean unknown (0). A
// session whose status is `recording` or `failed` is read up to its last
// complete pair: frames.csv.part is used when frames.csv is absent, a
// truncated last line is ignored, and trailing rows without both images are
// dropped (counted in `dropped_tail`). In a `complete` session every row
// needs both images.
//
// Images are located, not decoded (data/ has no image library): a caller
// that decodes them reports an unreadable image as InputError naming it.

#include <string>
#include <vector>

namespace kincal {

struct SessionFrame {
  int frame = 0;           // the `frame` column
  double t_left = 0.0;     // s
  double t_right = 0.0;    // s
  long long seq_left = 0;  // camera sequence numbers
  long long seq_right = 0;
  std::string left_image;  // full paths
  std::string right_image;
  // Joint readings in the order of ReadSession's `joint_names` (interface
  // units: mm | deg); empty when the row's joint cells are empty.
  std::vector<double> q;
  bool HasJoints() const { return !q.empty(); }
  int line = 0;  // line in frames.csv (1-based), for messages
};

struct Session {
  std::string dir;
  std::string status;                      // complete | failed | recording
  std::string frames_csv;                  // the file the rows came from
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
};

// Reads the session folder `dir`. Strict: every problem is InputError with
// file:line:column and what was expected.
Session ReadSession(const std::string& dir,
                    const SessionReadOptions& options = {});

// Parses frames.csv text (exposed for tests): fills frames (without image
// paths), joint_columns; `partial` = the session is unfinished, so a last
// line without a newline is ignored.
void ParseSessionFramesCsv(const std::string& text, const std::string& file,
                           const SessionReadOptions& options, bool partial,
                           Session* session);

}  // namespace kincal

#endif  // KINCAL_DATA_SESSION_H_
