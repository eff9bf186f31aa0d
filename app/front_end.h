#ifndef KINCAL_APP_FRONT_END_H_
#define KINCAL_APP_FRONT_END_H_

// kincal is two executables with one command surface (docs/STARTUP.md):
//
//   bin/kincal         every command that reads and writes no images
//                      (calibrate, evaluate, diagnose, ...): links no image
//                      codecs, video I/O, camera SDKs (~30 shared libraries)
//   bin/kincal-vision  every command, built from the same sources (OpenCV's
//                      imgcodecs and videoio alone bring GDAL, HDF5,
//                      GStreamer...: ~270 shared libraries, 0.2-0.3 s to load)
//
// In bin/kincal, the image commands (KINCAL_IMAGE_COMMANDS in
// app/CMakeLists.txt: camcal, track, capture, bundle, target, print) are
// registered by app/front_end.cc with their names and descriptions only (so
// `kincal --help` lists them) and accept any arguments; once CLI11 selects
// one, or `simulate` is given --render, kincal replaces itself by
// kincal-vision with the same argv (exec), so output, exit codes, provenance
// and every --help are those of one program.

namespace kincal::app {

// The image commands' descriptions in the command list, one text for both
// executables (cmd_<name>.cc registers the real command with it).
inline constexpr char kCamcalDescription[] =
    "Calibrate one camera or a stereo pair from images of a chessboard or an "
    "AprilGrid; writes rig.yaml";
inline constexpr char kTrackDescription[] =
    "Needle tip in the rig frame for every stereo frame pair, from the tool's "
    "AprilTags (writes points.csv and <out>.poses.csv)";
inline constexpr char kCaptureDescription[] =
    "Record a session (one image folder per camera, named as in rig.yaml; "
    "frames.csv, session.yaml) from 1..N cameras or recordings "
    "(--camera NAME=URI each, or --left/--right for two); --list shows "
    "cameras. "
    "Sources: v4l2:/dev/videoN?width=..&height=..&fps=..&format=GREY|YUYV|"
    "MJPG, aravis:<camera id>?exposure_us=..&gain=..&fps=..&format=Mono8|..., "
    "folder:/path/left*.png?fps=.., video:/path/file.mp4";
inline constexpr char kBundleDescription[] =
    "Calibrate the robot from a recorded session's images: one Ceres problem "
    "over every tag corner in every camera at every frame with joint readings "
    "(robot parameters, base in the rig and target on the flange, or with "
    "rig.yaml mount: flange the rig on the flange and the fixed target in the "
    "base; optionally the cameras)";
inline constexpr char kTargetDescription[] =
    "Measure a tool target from a recorded session of the tool: the tag "
    "poses from one bundle over every tag corner, the needle tip by pivot "
    "calibration (--pivot); writes target.yaml with sigmas";
inline constexpr char kPrintDescription[] =
    "Write a print-ready calibration sheet (PDF or SVG, physical size, with a "
    "100 mm scale bar) of a camcal target spec or a tool's target.yaml";

// Replaces this process by kincal-vision with this process's argv (read
// from /proc/self/cmdline). kincal-vision is $KINCAL_VISION when set, else
// the kincal-vision next to this executable, else
// <dir>/../libexec/kincal/kincal-vision. Returns only on failure (message on
// stderr; exit code 1: an incomplete installation, not bad input).
int ExecImageBinary();

}  // namespace kincal::app

#endif  // KINCAL_APP_FRONT_END_H_
