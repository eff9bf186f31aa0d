#include "camcal/board_warp.h"

#include <algorithm>
#include <limits>

namespace kincal {

BoardExtent BoardExtent::Of(const std::vector<Eigen::Vector3d>& points) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  BoardExtent e{kInf, -kInf, kInf, -kInf};
  for (const Eigen::Vector3d& p : points) {
    e.x_min = std::min(e.x_min, p.x());
    e.x_max = std::max(e.x_max, p.x());
    e.y_min = std::min(e.y_min, p.y());
    e.y_max = std::max(e.y_max, p.y());
  }
  if (!(e.x_max > e.x_min)) {
    e.x_min = points.empty() ? 0.0 : e.x_min;
    e.x_max = e.x_min + 1.0;
  }
  if (!(e.y_max > e.y_min)) {
    e.y_min = points.empty() ? 0.0 : e.y_min;
    e.y_max = e.y_min + 1.0;
  }
  return e;
}

}  // namespace kincal
