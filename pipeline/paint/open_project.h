// Opens a project for painting: loads its capture (scene, cameras, poses; the video is read
// lazily) and builds the PaintSession (grouping, base buffers). Shared by `fresco run` and
// `fresco group` and the app. Errors are bad input (exit 2), naming the file and field.
#pragma once

#include <memory>
#include <vector>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/paint/paint_session.h"

namespace fresco {

// A project with one video stream (a version-1 file, or version 2 with one entry in
// `streams`); a project with several is an error naming `streams`.
Status OpenPaintSession(const Project& project, Capture* capture,
                        std::unique_ptr<PaintSession>* session);
// The same with the capture's load options (e.g. open_video false: a live video is opened
// later, once the pose feed is connected).
Status OpenPaintSession(const Project& project, const CaptureLoadOptions& load_options,
                        Capture* capture, std::unique_ptr<PaintSession>* session);
// Every video stream of the project (LoadStreamCaptures: the scene is in (*streams)[0]),
// painting one model. The automatic texel size is the finest any stream asks for (each
// stream's first camera at its own poses).
Status OpenPaintSession(const Project& project, const CaptureLoadOptions& load_options,
                        std::vector<Capture>* streams, std::unique_ptr<PaintSession>* session);
// The session over streams loaded already (LoadStreamCaptures), its buffers laid out as
// `layout` says when given (PaintSessionInputs::layout: hollow until SetOwnBuffers).
// `layout_only`: PaintSessionInputs::layout_only.
Status CreatePaintSession(const Project& project, const std::vector<Capture>& streams,
                          const BufferLayout* layout, std::unique_ptr<PaintSession>* session,
                          bool layout_only = false);

}  // namespace fresco
