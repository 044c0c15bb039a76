// A tag corner where no saddle is: Kalibr prints a black square where the gaps between tags
// cross, so each tag corner is a saddle cv::cornerSubPix finds without bias; boards drawn
// without those squares (OpenCV's GridBoard, most home-made AprilGrids) leave each tag corner
// the convex corner of a black square on white, which blur and anti-aliasing round off and
// cornerSubPix pulls into the tag (0.17 px sharp, 0.31 px blurred 1 px: the tag shrinks
// against the board's pitch, and a solve takes that for lens distortion). There the corner
// is the meeting point of the tag's two edges: each edge located to sub-pixel along its
// normal (where the grey crosses halfway between the edge's dark and light levels, taken
// 2.5 px or more to either side, so that blur moves it neither way; then moved to where a
// step has the grey's area about that crossing, which a sharp edge's crossing interpolated
// between pixels is not) along the whole edge, fitted by a quadratic (a lens bends the
// edge), and the two curves intersected.
#pragma once

#include <array>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace fresco::calib {

// Whether the board has a black square at tag corner k (the tag's corners `p`, in order
// around it): the grey just outside the corner, on the diagonal away from the tag's centre,
// is nearer the tag's black than the white of its gap, and the gaps on either side of the
// square (halfway across each, next to the corner) are white. `gray` is CV_8U.
bool CrossingSquareAt(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& p, int k);

// Corner k as the intersection of the tag's two edges through it, or false (then `corner`
// is untouched) when an edge shows too little contrast or the result lies more than
// max(1.5 px, 5 % of the tag's edge) from p[k]. Also false, with `left_out` set, when the
// two edges' light levels differ by more than 8 % of the range (an outer tag's edge beside a
// paper margin of a few pixels blurred onto a dark surround: no level places it): the corner
// is to be left out, not refined otherwise.
// `levels`, when given and both edges were found: the edges' dark level and the lighter one's
// light level.
// `level`: where between the edge's dark (0) and light (1) levels each cut places the edge;
// halfway (0.5) is the printed edge when the grey is linear in the light (calib/tag_dilation.h
// finds the one for a tone curve).
// `border_bits`: the tag's black border (1 or 2 bits of its 8 or 10): an edge too short for its
// levels to be read near the corner is placed only where the border along it is 2.5 px thick
// or more.
bool CornerFromEdges(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& p, int k,
                     Eigen::Vector2d* corner, bool* left_out = nullptr,
                     std::array<double, 2>* levels = nullptr, double level = 0.5,
                     int border_bits = 1);

// An edge whose light level lies more than this part of the dark-to-light range below that of
// the other edges of its tag is beside a margin too narrow for its blur: its corner is left out.
constexpr double kMaxEdgeLightDeficit = 0.08;

}  // namespace fresco::calib
