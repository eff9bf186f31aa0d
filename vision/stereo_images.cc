#include "vision/stereo_images.h"

#include <algorithm>
#include <exception>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>
#include <vector>

#include "data/error.h"

namespace kincal {

cv::Mat ReadCameraImage(const std::string& path, const CameraIntrinsics& cam,
                        BayerPattern bayer, BayerBalance* balance) {
  const cv::Mat im = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (im.empty()) {
    throw InputError(path +
                     ": cannot read the image (not an image file, or "
                     "truncated)");
  }
  if (im.cols != cam.width || im.rows != cam.height) {
    std::ostringstream os;
    os << path << ": image is " << im.cols << "x" << im.rows << " but camera '"
       << cam.name << "' in the rig is " << cam.width << "x" << cam.height;
    throw InputError(os.str());
  }
  return BalanceBayerMosaic(im, bayer, balance);
}

void ForBothCameras(const std::function<void(int camera)>& work) {
  ForEachCamera(2, work);
}

void ForEachCamera(int n, const std::function<void(int camera)>& work) {
  std::vector<std::string> error(std::max(n, 0));
  auto guarded = [&](int first) {
    for (int c = first; c < n; c += 2) {
      try {
        work(c);
      } catch (const std::exception& e) {
        error[c] = e.what();
      }
    }
  };
  if (n > 1) {
    std::thread second(guarded, 1);
    guarded(0);
    second.join();
  } else {
    guarded(0);
  }
  for (const std::string& e : error) {
    if (!e.empty()) throw InputError(e);
  }
}

}  // namespace kincal
