// fresco group PROJECT.json [--set KEY=VALUE ...] [--save] [--json FILE]: shows the project's
// base-buffer grouping (paper §3.6) as `fresco run` will use it: per group its triangles,
// normal, area, texel size, buffer size and texels. --save stores it in the project as
// explicit groups (grouping.groups; edits folded in, fold-over splits included), atomically,
// so that it can be edited by hand or in the app and stays fixed whatever the automatic
// grouping does later.
#include <cstdio>
#include <iostream>

#include <vector>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "pipeline/paint/open_project.h"
#include "pipeline/core/atomic_file.h"

namespace fresco {
namespace {

ArgSpec GroupSpecArgs() {
  ArgSpec spec;
  spec.usage = "fresco group PROJECT.json [--set KEY=VALUE ...] [--save] [--json FILE]";
  spec.help =
      "Shows the base-buffer grouping `fresco run` will use: neighbouring triangles with\n"
      "similar normals share a buffer (grouping.angle_deg), unless the project lists its\n"
      "groups (grouping.groups); grouping.edits then apply (merge, split, move, texel).\n\n"
      "  --set KEY=VALUE   override a project setting, e.g. --set grouping.angle_deg=30\n"
      "  --save            store the grouping in the project as explicit groups (atomic)\n"
      "  --json FILE       also write the table as JSON";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--json"};
  spec.repeatable = {"--set"};
  spec.switches = {"--save"};
  return spec;
}

}  // namespace

int RunVerbGroup(const CommandArgs& argv) {
  const ArgSpec spec = GroupSpecArgs();
  Args args;
  if (int code = ParseVerbArgs("group", argv, spec, &args); code >= 0) return code;
  Project project;
  if (Status s = LoadProject(args.positional[0], args.All("--set"), &project); !s.ok())
    return Fail(s);
  std::vector<Capture> streams;  // every stream's poses choose the automatic texel size
  std::unique_ptr<PaintSession> session;
  if (Status s = OpenPaintSession(project, CaptureLoadOptions(), &streams, &session); !s.ok())
    return Fail(s);

  const TriangleMesh& mesh = streams[0].scene.mesh;
  nlohmann::json table = nlohmann::json::array();
  std::printf("%5s %9s %22s %9s %9s %11s %10s\n", "group", "triangles", "normal (x, y, z)",
              "area m2", "texel m", "buffer", "texels");
  long long texels = 0;
  for (size_t g = 0; g < session->buffers().size(); ++g) {
    const BaseBuffer& b = session->buffers()[g];
    double area = 0;
    for (int t : b.triangles) area += mesh.Area(t);
    std::printf("%5zu %9zu %6.3f, %6.3f, %6.3f %9.3f %9.5f %5dx%-5d %10d\n", g, b.triangles.size(),
                b.normal.x(), b.normal.y(), b.normal.z(), area, b.texel_size_m, b.width, b.height,
                b.num_surface_texels);
    texels += b.num_surface_texels;
    table.push_back({{"group", g},
                     {"triangles", b.triangles.size()},
                     {"normal", {b.normal.x(), b.normal.y(), b.normal.z()}},
                     {"area_m2", area},
                     {"texel_size_m", b.texel_size_m},
                     {"width", b.width},
                     {"height", b.height},
                     {"texels", b.num_surface_texels}});
  }
  int ungrouped = 0;
  for (int owner : session->grouping().group_of_triangle) ungrouped += owner < 0;
  std::printf(
      "%zu base buffers for %d triangles (%d in no group), %lld texels; %d groups split "
      "because one projection could not serve them\n",
      session->buffers().size(), mesh.NumTriangles(), ungrouped, texels, session->folds_split());
  if (args.Has("--json")) {
    const nlohmann::json out = {{"base_buffers", session->buffers().size()},
                                {"triangles", mesh.NumTriangles()},
                                {"ungrouped_triangles", ungrouped},
                                {"texels", texels},
                                {"groups", table}};
    if (Status s = WriteFileAtomic(args.Get("--json"), out.dump(2) + "\n"); !s.ok()) return Fail(s);
  }
  if (args.Switch("--save")) {
    Project saved;  // the file as written, without --set overrides, plus the grouping
    if (Status s = LoadProject(args.positional[0], {}, &saved); !s.ok()) return Fail(s);
    saved.grouping.groups = session->grouping().groups;
    saved.grouping.edits.clear();
    if (Status s = SaveProject(saved, saved.file_path); !s.ok()) return Fail(s);
    std::printf("saved %zu groups to %s\n", saved.grouping.groups.size(), saved.file_path.c_str());
  }
  return kExitOk;
}

}  // namespace fresco
