#include "calib/detect_aruco.h"

#include <opencv2/aruco.hpp>

namespace fresco::calib {

const int kArucoToApriltag[4] = {1, 0, 3, 2};

std::vector<TagQuad> DetectTagsAruco(const cv::Mat& gray, int num_ids, int border_bits) {
  cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->markerBorderBits = border_bits;
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, dictionary, corners, ids, params);
  std::vector<TagQuad> out;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] < 0 || ids[i] >= num_ids || corners[i].size() != 4) continue;
    TagQuad quad;
    quad.id = ids[i];
    quad.border_bits = border_bits;
    for (int k = 0; k < 4; ++k)
      quad.p[kArucoToApriltag[k]] = Eigen::Vector2d(corners[i][k].x, corners[i][k].y);
    out.push_back(quad);
  }
  return out;
}

}  // namespace fresco::calib
