// A labelled path input with a "..." button listing the entries of the typed folder that fit
// (BrowseEntries), shared by the New project form and the Project panel's path editor; and
// the extensions each of a project's paths offers there.
#pragma once

#include <string>
#include <vector>

namespace fresco {

// `id`: the input's ImGui id ("##scene"), unique in its window. Returns true when the value
// changed (typed or picked).
bool PathField(const char* label, const char* id, const char* hint, std::string* value,
               const std::vector<std::string>& extensions);

// The project's four paths as PathField edits them (the hints and "..." extensions of the
// scene, video, camera and poses). Returns true when one changed.
struct ProjectPaths;
bool ProjectPathFields(ProjectPaths* paths);
// The scene, video and camera fields of ProjectPathFields, and its poses field (with another
// hint: the New project form's rough poses for a bootstrap).
bool SceneVideoCameraFields(ProjectPaths* paths);
bool PosesField(std::string* poses,
                const char* hint = "COLMAP images.txt, TUM file, or tcp:// live feed");

}  // namespace fresco
