#ifndef KINCAL_APP_APP_UTIL_H_
#define KINCAL_APP_APP_UTIL_H_

// Small helpers shared by the subcommands: reading inputs, writing outputs
// atomically, JSON conversions. No algorithms here.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/fit.h"
#include "calib/identifiability.h"
#include "calib/outliers.h"
#include "data/observations.h"
#include "data/robot.h"
#include "data/warnings.h"
#include "vision/bayer.h"

namespace kincal::app {

// The robot-input option group: --robot FILE (robot.yaml or .urdf, with
// `robot_help`), then --root and --tip, the URDF links the chain runs
// between. Returns the --robot option (callers add ->required()).
CLI::Option* AddRobotOptions(CLI::App* sub, std::string* robot,
                             std::string* root, std::string* tip,
                             const std::string& robot_help,
                             const std::string& root_help = "URDF root link",
                             const std::string& tip_help = "URDF tip link");

// A command's --help footer: `example`, then the units line (with
// `units_note` before its full stop) and where the defaults are shown.
std::string HelpFooter(const std::string& example,
                       const std::string& units_note = "");

// The image globs of a command's cameras (format v3): `--camera NAME=GLOB`,
// repeatable, in rig order; or the two-camera spelling `--left GLOB
// [--right GLOB]` (cameras named left and right). `option` is how the user
// wrote it, for messages.
struct CameraGlob {
  std::string name, glob, option;
};
// Adds --camera (repeatable) to `sub`, with `help`.
CLI::Option* AddCameraOption(CLI::App* sub, std::vector<std::string>* cameras,
                             const std::string& help);
// InputError for a --camera without NAME= or GLOB, a name given twice, a
// --right without --left, or --camera mixed with --left/--right. Empty when
// none is given.
std::vector<CameraGlob> CameraGlobs(const std::vector<std::string>& cameras,
                                    const std::string& left,
                                    const std::string& right);
// `globs` in the order of the rig's cameras: --camera names must be the
// rig's (each once, every one given); --left/--right stand for the rig's
// first and second camera (and --left alone for a one-camera rig).
// InputError naming the camera otherwise. `rig_file` for messages.
std::vector<CameraGlob> InRigOrder(const std::vector<CameraGlob>& globs,
                                   const std::vector<std::string>& rig_names,
                                   const std::string& rig_file);

// Creates `dir` (and parents) if needed; InputError when it cannot.
void MakeDirs(const std::string& dir);

// JSON number, or null when not finite.
nlohmann::json Number(double v);

// {"n", "rms_mm", "mean_mm", "max_mm", "std_mm"}
nlohmann::json StatsJson(const ErrorStats& s);

// Per free parameter: name, value, sigma (interface units), nominal.
nlohmann::json ParametersJson(const FitSummary& fit, const ModelState& nominal);

// Gross-error rows (calib/outliers.h) as a JSON array: pose, row, error_mm,
// sigmas, excluded, heldout, near_point / near_point_mm when set.
nlohmann::json OutliersJson(const std::vector<RowOutlier>& outliers);

// The same in words, one line each after a header line; nothing when empty.
void PrintOutliers(const std::vector<RowOutlier>& outliers,
                   double axis_sigma_mm, double sigmas);

// Reads observations.csv for `robot` (read from `robot_file`) and checks
// them against it (data/observation_checks.h): InputError for readings
// outside the joint limits or points in metres; warnings (e.g. radians) into
// `warnings`. The one place the commands that take --robot and --obs load
// their observations.
Observations ReadCheckedObservations(const std::string& path,
                                     const Robot& robot,
                                     const std::string& robot_file,
                                     Warnings* warnings);

// Adds `warnings` to a result as "warnings": [{code, message}, ...]; nothing
// when there are none (outputs of good inputs keep their fields).
void AddWarnings(const std::vector<Warning>& warnings, nlohmann::json* j);
inline void AddWarnings(const Warnings& warnings, nlohmann::json* j) {
  AddWarnings(warnings.list(), j);
}

// Adds the warning "poses_leave_robot_undetermined" when the poses of
// `obs` with a measured tip leave robot parameters undetermined that poses
// over the joints' limits would determine (calib/pose_coverage.h): it names
// them, the joints' seen travel, and points to `kincal bundle` and `kincal
// plan --rig`. For calibrate and track --out-obs.
void WarnPoseCoverage(const Robot& nominal, const Observations& obs,
                      Warnings* warnings);

// Refuses (InputError) a camera whose images never show a tag of the target
// while another camera's do (spec v3): wrong folder, wrong camera, or a
// camera looking elsewhere. Per camera c (rig order): `tag_counts[c]`, its
// frames (or corners) with a target tag; `cameras[c]`, its name; `images[c]`,
// where its images are (folder or option). `rig_file` and `frames` (the
// frames looked through, e.g. "the 12 frames with joint readings of S") are
// for the message, which names the camera, its images and the fix. Nothing
// when no camera shows a tag: the tool was not there, or the caller's own
// check says more.
void RefuseBlindCameras(const std::vector<int>& tag_counts,
                        const std::vector<std::string>& cameras,
                        const std::vector<std::string>& images,
                        const std::string& rig_file, const std::string& frames);

// Adds --bayer PATTERN to `sub` (images are a colour camera's raw mosaic,
// balanced to gray before detection; vision/bayer.h). Left empty when not
// given: ChooseBayerPattern then asks session.yaml.
CLI::Option* AddBayerOption(CLI::App* sub, std::string* pattern);
// The pattern to read the images with: --bayer when given (`option`: a
// pattern or none); else the one session.yaml records for the cameras
// (`session_mosaics`, Session::mosaics: `capture` with bayer=raw writes
// it), said on stderr; none when it records none. InputError when the
// cameras record different patterns (one pattern is read for all); the
// warning `bayer_differs_from_session` when --bayer contradicts a pattern
// it records (a session.yaml without one says nothing either way).
BayerPattern ChooseBayerPattern(const std::string& option,
                                const std::vector<std::string>& session_mosaics,
                                const std::string& session_dir,
                                Warnings* warnings);
// The warning for `doubtful` of `images` images whose Bayer balance looked
// wrong (green phases apart, or no bright flat paper): the images may not be
// a raw mosaic of `pattern`.
void WarnDoubtfulBayer(int doubtful, int images, BayerPattern pattern,
                       Warnings* warnings);
// The warning for `cameras` cameras whose images, read as gray, look like
// a raw Bayer mosaic (LooksLikeRawMosaic): --bayer names the pattern.
void WarnRawMosaic(int cameras, Warnings* warnings);

// `cameras` cameras' images look demosaiced by the camera
// (SessionObservations::looks_demosaiced): warning images_demosaiced,
// which names what the bundle loses and how to record the raw mosaic.
void WarnDemosaiced(int cameras, Warnings* warnings);

// A command's warnings list: each warning goes to stderr as it is found (in
// JSON mode too, so that a later refusal still shows it) and into the JSON
// result through AddWarnings.
Warnings CommandWarnings();

}  // namespace kincal::app

#endif  // KINCAL_APP_APP_UTIL_H_
