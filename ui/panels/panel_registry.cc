// Every panel of the app, in the View menu's order, with where it starts in a 1600 x 1000
// window (four columns, nothing overlapping; scaled to the real window): one line each.
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
  Add(&p, MakeProjectPanel(), 0, 20, 330, 200);
  Add(&p, MakePipelinePanel(), 0, 220, 330, 470);
  Add(&p, MakeTimingPanel(), 0, 690, 330, 285);
  Add(&p, MakeInputFramePanel(), 330, 20, 420, 300);
  Add(&p, MakeStagePanel("depth", "Stage: depth and visibility"), 330, 320, 420, 330);
  Add(&p, MakeViewportPanel(), 330, 650, 420, 325);
  Add(&p, MakeStagePanel("warp", "Stage: warp to buffer"), 750, 20, 420, 300);
  Add(&p, MakeStagePanel("paint", "Stage: paint"), 750, 320, 420, 330);
  Add(&p, MakeMisalignmentPanel(), 750, 650, 420, 325);
  Add(&p, MakePaintedBuffersPanel(), 1170, 20, 430, 300);
  Add(&p, MakeGroupingPanel(), 1170, 320, 430, 655);
  return p;
}

}  // namespace fresco
