// An evaluation suite: a list of synthetic captures, each a `fresco synth` spec with a seed,
// grouped into families (room, street, façade, blocks, ...), that `fresco eval` paints with
// one setting and scores. The suite file names what varies (scene, path, lens, frames, pose
// noise, movers, exposure); the captures themselves are generated on demand and cached.
//
// Suite file:
//   {
//     "fresco_eval_suite": 1,               // format version (optional)
//     "defaults": {...},                    // synth spec keys under every capture (optional)
//     "captures": [
//       {"name": "room-turn", "family": "room",
//        "synth": {...},                    // a synth spec (synth_spec.h) without "out"
//        "seeds": [1, 2, 3]},               // optional: one capture per seed, "room-turn-s2"
//       ...
//     ]
//   }
// A capture's spec is "defaults" with its "synth" merged over it (JSON merge patch).
// Parsing is strict: unknown keys, duplicate names and bad synth specs are errors naming
// the suite file and the field ("suite.json: captures[3].synth: frames: must be ...").
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/synth/synth_spec.h"

namespace fresco {

struct SuiteCapture {
  std::string name;       // unique in the suite; [A-Za-z0-9._-]; the cache folder's name
  std::string family;     // the group its figures are summarised in
  std::string spec_text;  // the merged synth spec (JSON)
  std::string spec_name;  // for messages: "suite.json: captures[3].synth"
};

struct EvalSuite {
  std::string path;      // the suite file
  std::string base_dir;  // relative paths in specs resolve against it (the suite's folder)
  std::vector<SuiteCapture> captures;
};

// Reads and checks a suite file; every capture's spec is built once (BuildSynthJob), so a
// typo anywhere fails before anything runs.
Status LoadEvalSuite(const std::string& path, EvalSuite* suite);

// Builds one capture's synth job (scene and options; out_dir left empty).
Status BuildSuiteCaptureJob(const EvalSuite& suite, const SuiteCapture& capture, SynthJob* job);

// Keeps only the captures named in `names` (each a capture or a family name); an unknown
// name is an error naming it.
Status SelectSuiteCaptures(const std::vector<std::string>& names, EvalSuite* suite);

}  // namespace fresco
