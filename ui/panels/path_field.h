// A labelled path input with a "..." button listing the entries of the typed folder that fit
// (BrowseEntries), shared by the New project form, the Project panel's path editor, the File
// menu's Open and Save As and the Calibration panel; and the extensions each of a project's
// paths offers there. A list starts in the folder its field names, or, when the field is
// empty, in the last folder used anywhere in the app (`last_folder`, the app's
// AppState::last_folder: the last list's, or the project's). Escape closes it (the app's
// shortcuts close whatever menu or list is on top).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace fresco {

struct PathFieldOptions {
  std::vector<std::string> extensions;  // the files the list offers (folders always)
  // A folder of images is itself a value (a video's frames, calibration pictures): the list
  // of such a folder says how many images it holds instead of "nothing here fits".
  bool folder_of_images = false;
  float min_width_px = 40;  // the input's least width (a menu grows to fit it)
  // The last folder a list was used in (absolute, ending in '/'): an empty field's list
  // starts there; a pick or a typed path that names an existing folder updates it.
  std::string* last_folder = nullptr;
};

// `id`: the input's ImGui id ("##scene"), unique in its window. Returns true when the value
// changed (typed or picked).
bool PathField(const char* label, const char* id, const char* hint, std::string* value,
               const PathFieldOptions& options);

// A click outside an open "..." list closes it and reaches what it was on: ImGui alone would
// only close the list, and a field clicked so stayed inactive (the text typed next was lost).
// Each PathField calls it; the app calls it once a frame before the panels too, for what is
// drawn before them.
void LetAClickOutsideABrowseListThrough();

// The project's four paths as PathField edits them (the hints and "..." extensions of the
// scene, video, camera and poses). Returns true when one changed.
struct ProjectPaths;
bool ProjectPathFields(ProjectPaths* paths, std::string* last_folder);
// The scene, video and camera fields of ProjectPathFields, and its poses field (with another
// hint: the New project form's rough poses for a bootstrap).
bool SceneVideoCameraFields(ProjectPaths* paths, std::string* last_folder);
bool PosesField(std::string* poses, std::string* last_folder,
                const char* hint = "COLMAP images.txt, TUM file, or tcp:// live feed");

// What a path list says above its entries: for a folder of images (options.folder_of_images)
// "this folder: 12 images", with " (chosen)" when `value` is that folder (ends in '/');
// else "nothing here fits" when `entries` (BrowseEntries' count) is 0; else "".
std::string BrowseNote(const std::string& value, const PathFieldOptions& options, size_t entries);

// How many images (.png, .jpg, .jpeg, .bmp, .tif, .tiff) the folder `folder` holds.
int CountImages(const std::string& folder);

}  // namespace fresco
