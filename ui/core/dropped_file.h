// Files dropped onto the app's window: what each one is (by its extension, and for .json
// and .txt files by what they hold), and where the app puts it: a project opens, a scene,
// video, camera or poses file fills that field of the New project form when it is open,
// else of the Project panel's path editor (the open project's, or the one that did not
// open); anything else is one status message. The window's drop callback hands the paths to
// DropPaths; DrawAppFrame places them. Classification is pure: tests call it directly.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace fresco {

enum class DroppedKind { kProject, kScene, kVideo, kCamera, kPoses, kUnknown };

struct DroppedFile {
  DroppedKind kind = DroppedKind::kUnknown;
  std::string path;  // as dropped; a folder ends in '/'
  std::string why;   // kUnknown: one line naming the file and what it is not
};

// What `path` is: a Fresco project (.json with a "fresco" key), a mesh (.gltf, .glb, .ply,
// .obj), a video (a video file or a folder of frames), a camera (.cameramodel, or a COLMAP
// cameras.txt), poses (.tum, a COLMAP images.txt or a TUM text file), or unknown (missing,
// unreadable or none of these).
DroppedFile ClassifyDroppedPath(const std::string& path);

// "project", "scene", "video", "camera", "poses", "unknown".
const char* DroppedKindName(DroppedKind kind);

struct UiContext;
class Panel;
// The entry point of the window's drop callback (and of tests): queues the paths for the
// next DrawAppFrame.
void DropPaths(UiContext& ui, const std::vector<std::string>& paths);
// Places the queued paths (DrawAppFrame calls it first thing): opens a project, hands a
// field's file to the New project form (when open) or the Project panel (Panel::AcceptDrop),
// and says what happened in the status bar.
void PlaceDroppedPaths(UiContext& ui, std::vector<std::unique_ptr<Panel>>& panels);

}  // namespace fresco
