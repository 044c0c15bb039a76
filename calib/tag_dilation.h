// Tags grown or shrunk by the camera's tone curve. Where a tag corner is taken from the tag's
// edges (no black square at it: calib/tag_corner_edges.h), each edge lies where the grey
// crosses halfway between black and white; under a blur that is the printed edge only when the
// grey is linear in the light. A gamma or contrast curve moves the halfway crossing of every
// blurred edge outwards (the black grows: gamma > 1) or inwards by the same distance, so every
// tag looks larger or smaller against the board's pitch, which a solve takes for lens
// distortion (gamma 2, blur 1 px, JPEG 80: tags 0.7 px larger, the lens 0.57 px RMS from the
// truth). The pitch itself does not move: along a row of two neighbouring tags the four
// corners' cross ratio (perspective keeps it) gives how far each edge moved, the median over
// the image's tag pairs one figure for the image. The detector (calib/detect.cc) then looks for
// the edge level (between each edge's dark and light, 0.5 halfway) at which that figure is 0,
// from the figures at two levels: each edge then moves by its own ramp's share of the tone
// curve, where one shift undone at every edge leaves each edge its difference from the
// median; what is left at that level is undone as below.
#pragma once

#include <map>
#include <vector>

#include "calib/board.h"
#include "calib/detect.h"

namespace fresco::calib {

// How far (px, along the edges' normals, > 0: outwards) the edges of the image's tags moved,
// from the pairs of neighbouring tags whose 4 corners along the row (or column) are all in
// `from_edges`; 0 when fewer than `min_pairs` pairs are. `corners` sorted by id.
double TagEdgeShift_px(const BoardSpec& spec, const std::vector<CornerObservation>& corners,
                       const std::vector<bool>& from_edges, int min_pairs = 6);

// Moves each corner with from_edges[i] set as if both its tag's edges through it moved by
// -shift_px along their outward normals. The tag's other corners give the edges' directions;
// where one is missing (left out: an outer tag's corner beside a narrow paper margin), the
// tag's outline as read (`outlines`, by tag id), and without that the corner is left as it is.
void ShiftTagEdges(double shift_px, const std::vector<bool>& from_edges,
                   std::vector<CornerObservation>* corners,
                   const std::map<int, TagQuad>* outlines = nullptr);

}  // namespace fresco::calib
