#ifndef KINCAL_VISION_STEREO_IMAGES_H_
#define KINCAL_VISION_STEREO_IMAGES_H_

// Reading a recorded frame for tag detection: each image checked against
// its camera in the rig, and the cameras worked on two at once.

#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "camcal/camera_model.h"
#include "vision/bayer.h"

namespace kincal {

// The image at `path` as 8-bit gray. InputError when it cannot be read or
// its size is not the camera's in the rig. With a Bayer pattern the file
// holds a camera's raw mosaic, balanced to gray here (vision/bayer.h);
// `balance` (optional) receives what was measured.
cv::Mat ReadCameraImage(const std::string& path, const CameraIntrinsics& cam,
                        BayerPattern bayer = BayerPattern::kNone,
                        BayerBalance* balance = nullptr);

// Runs work(0) and work(1) on two threads. An exception in either is
// carried back and thrown here as InputError (the first camera's first).
void ForBothCameras(const std::function<void(int camera)>& work);

// Runs work(c) for c = 0..n-1 on two threads (even cameras on this one, odd
// on the other; 2 at a time is what a tag detector's memory bandwidth
// rewards). An exception is carried back and thrown here as InputError (the
// lowest camera's first).
void ForEachCamera(int n, const std::function<void(int camera)>& work);

}  // namespace kincal

#endif  // KINCAL_VISION_STEREO_IMAGES_H_
