#ifndef KINCAL_REPORT_CAMERA_SECTIONS_H_
#define KINCAL_REPORT_CAMERA_SECTIONS_H_

// The report's sections about the cameras (report/report.h lists them all):
//
//   camera    rig intrinsics and baseline; with camcal's JSON the RMS, sigma
//             of the intrinsics, the error per view and over the image
//             (camcal's image_grid: RMS and mean residual vector per cell)
//             and the projection uncertainty map (camcal's
//             projection_uncertainty grid) as a heat map
//   tracking  tip quality per frame (points.csv of kincal track)

#include <nlohmann/json.hpp>
#include <string>

#include "camcal/rig.h"
#include "report/html.h"

namespace kincal {

// `camcal` is what `kincal camcal --json` printed (null when not given),
// read from `camcal_path`.
void AddCameraSection(const Rig& rig, const nlohmann::json& camcal,
                      const std::string& camcal_path, HtmlReport* page);

// `exists`: whether points_path is there (else the section says how to make
// it). Throws InputError when the file is not track's points.csv.
void AddTrackingSection(const std::string& points_path, bool exists,
                        HtmlReport* page);

}  // namespace kincal

#endif  // KINCAL_REPORT_CAMERA_SECTIONS_H_
