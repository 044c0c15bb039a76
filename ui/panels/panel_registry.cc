// Every panel of the app, in the View menu's order, with where it would start floating in a
// 1600 x 1000 window (scaled to the real window): one line each. The tiled layout
// (DefaultTileLayout) places them all: Calibration, Poses and New project, closed at first,
// open as tabs in the stage row's place below the 3D view.
#include "ui/panels/panels.h"

namespace fresco {
namespace {

void Add(std::vector<std::unique_ptr<Panel>>* panels, std::unique_ptr<Panel> panel, float x,
         float y, float w, float h) {
  panel->default_pos = ImVec2(x, y);
  panel->default_size = ImVec2(w, h);
  panels->push_back(std::move(panel));
}

}  // namespace

std::vector<std::unique_ptr<Panel>> MakePanels() {
  std::vector<std::unique_ptr<Panel>> p;
  Add(&p, MakeProjectPanel(), 0, 20, 320, 190);
  Add(&p, MakePipelinePanel(), 0, 210, 320, 440);
  Add(&p, MakeTimingPanel(), 0, 650, 320, 325);
  Add(&p, MakeInputFramePanel(), 320, 20, 320, 280);
  Add(&p, MakeStagePanel("depth", "Stage: depth and visibility"), 320, 300, 320, 350);
  Add(&p, MakeViewportPanel(), 320, 650, 320, 325);
  Add(&p, MakeStagePanel("warp", "Stage: warp to buffer"), 640, 20, 320, 280);
  Add(&p, MakeStagePanel("background", "Stage: background"), 640, 300, 320, 350);
  Add(&p, MakeMisalignmentPanel(), 640, 650, 320, 325);
  Add(&p, MakeStagePanel("refine", "Stage: refine alignment"), 960, 20, 320, 280);
  Add(&p, MakeStagePanel("paint", "Stage: paint"), 960, 300, 320, 350);
  Add(&p, MakePaintedBuffersPanel(), 960, 650, 320, 325);
  Add(&p, MakeGroupingPanel(), 1280, 20, 320, 955);
  Add(&p, MakeCalibrationPanel(), 320, 20, 1280, 955);
  Add(&p, MakePosesPanel(), 320, 20, 1280, 955);
  Add(&p, MakeNewProjectDialog(), 360, 120, 760, 470);  // tall enough for a bootstrap's fields
  return p;
}

}  // namespace fresco
