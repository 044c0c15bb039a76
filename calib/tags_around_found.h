// A third look for the AprilGrid tags the detectors missed, around the ones they found: the
// found tags' corners give the board's homography near a missing tag (from the found tags
// within two places of it on the board), the image around the missing tag is resampled
// through it onto the board's plane (a straight-edged, upright tag: most of the lens's
// bending taken out), the detector looks there, and what it finds with the expected id and
// within a third of a tag edge of where the neighbours put it is mapped back into the image.
// Rounds repeat while they add tags (each found tag helps predict the next).
#pragma once

#include <functional>
#include <map>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/detect_aruco.h"

namespace fresco::calib {

// Runs a tag detector on a CV_8U image.
using TagDetector = std::function<std::vector<TagQuad>(const cv::Mat& gray)>;

// Adds to `found` (by id) the tags found this way; returns how many. `gray` is CV_8U.
int FindTagsAroundFound(const cv::Mat& gray, const BoardSpec& spec, const TagDetector& detect,
                        std::map<int, TagQuad>* found);

}  // namespace fresco::calib
