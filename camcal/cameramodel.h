#ifndef KINCAL_CAMCAL_CAMERAMODEL_H_
#define KINCAL_CAMCAL_CAMERAMODEL_H_

// mrcal's camera model file (`.cameramodel`), read and written for the lens
// models mrcal and kincal share. The file is a Python literal dict
// (mrcal reads it with ast.literal_eval), '#' comments allowed:
//
//   {
//     'lensmodel':  'LENSMODEL_OPENCV5',
//     'intrinsics': [ fx, fy, cx, cy, k1, k2, p1, p2, k3 ],
//     'valid_intrinsics_region': [ [u, v], ... ],   # optional, px
//     'extrinsics': [ rx, ry, rz, tx, ty, tz ],     # rt_cam_ref
//     'imagersize': [ width, height ],
//   }
//
// Lens models: LENSMODEL_PINHOLE (0 coefficients), LENSMODEL_OPENCV4 /
// OPENCV5 / OPENCV8 (OpenCV's k1 k2 p1 p2 [k3 [k4 k5 k6]], the same order
// and equations as camcal/camera_model.h). Others (OPENCV12, CAHVOR,
// CAHVORE, LATLON, LONLAT, STEREOGRAPHIC, SPLINED_STEREOGRAPHIC_...) are
// refused with an InputError that names the model.
//
// Pixel convention: mrcal's and OpenCV's agree ((0, 0) = centre of the
// top-left pixel), so intrinsics are copied as they are.
//
// Extrinsics: 'extrinsics' is mrcal's rt_cam_ref: a rotation vector r (rad)
// and translation t with p_in_cam = R(r) p_in_ref + t; here cam_from_ref.
// Units: mrcal's translations are in the units of the calibration board's
// spacing (metres in most mrcal calibrations); rig.yaml's are mm. The
// conversion is an explicit factor `unit_mm` = length of one model unit in
// mm (1000 for metres, 1 for mm) in RigFromCameraModels /
// CameraModelsFromRig; nothing guesses it.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "camcal/camera_model.h"
#include "camcal/rig.h"
#include "data/rigid3.h"

namespace kincal {

struct CameraModelFile {
  // Intrinsics; width/height from 'imagersize'. The name is not stored in
  // the file (callers set it).
  CameraIntrinsics intrinsics;
  // 'extrinsics' (rt_cam_ref), t in the file's units.
  Rigid3 cam_from_ref;
  // Optional closed polygon (px) where the intrinsics are trusted; empty
  // when the file has none.
  std::vector<Eigen::Vector2d> valid_intrinsics_region;
};

// mrcal's lens model name for `num_distortion` OpenCV coefficients:
// 0 -> LENSMODEL_PINHOLE, 4/5/8 -> LENSMODEL_OPENCV4/5/8. InputError for
// other counts.
std::string MrcalLensModelName(int num_distortion);

// Parses .cameramodel text; `file` is used in messages (file:line:column).
// Accepts mrcal's legacy key names ('distortion_model', 'lens_model') and
// 'DISTORTION_' model names; ignores keys it does not use
// ('optimization_inputs', 'icam_intrinsics', ...). InputError on syntax
// errors, missing keys, wrong counts, non-positive focal lengths or image
// sizes, and unsupported lens models.
CameraModelFile ParseCameraModel(const std::string& text,
                                 const std::string& file);
CameraModelFile ReadCameraModel(const std::string& path);

// The file text: a "# written by kincal ...: <command line>" comment, then
// mrcal's layout with every number written so that it reads back exactly.
std::string CameraModelToText(const CameraModelFile& model);
// Writes CameraModelToText(model) atomically (data/atomic_file.h).
void WriteCameraModel(const std::string& path, const CameraModelFile& model);

// A rig from named models: the first model's camera is the rig frame;
// cam_i_from_rig = cam_i_from_ref * (cam_0_from_ref)^-1 with t times
// `unit_mm` (mm); each camera keeps its valid_intrinsics_region. InputError
// when unit_mm <= 0, no models, or duplicate names.
Rig RigFromCameraModels(
    const std::vector<std::pair<std::string, CameraModelFile>>& models,
    double unit_mm);

// One model per camera of `rig`, extrinsics = cam_from_rig (the rig frame is
// the reference) with t divided by `unit_mm`, and the cameras'
// valid_intrinsics_region.
std::vector<CameraModelFile> CameraModelsFromRig(const Rig& rig,
                                                 double unit_mm);

}  // namespace kincal

#endif  // KINCAL_CAMCAL_CAMERAMODEL_H_
