// fresco merge PART_DIR... --out DIR: joins the parts `fresco run --shard I/N` wrote into the
// outputs one `fresco run` writes (pipeline/run/merge_parts.h).
#include <cstdio>

#include "app/commands.h"
#include "pipeline/run/merge_parts.h"

namespace fresco {
namespace {

ArgSpec MergeSpec() {
  ArgSpec spec;
  spec.usage = "fresco merge PART_DIR... --out DIR [--quiet]";
  spec.help =
      "Joins the N parts of one project that `fresco run PROJECT --out PART_DIR --shard I/N`\n"
      "wrote (one per I in 0..N-1, in any order) into exactly the outputs `fresco run` writes\n"
      "without --shard: DIR/painted.gltf with its .bin and atlas pages (each shard's charts\n"
      "from that shard), and DIR/metrics.json (texels and coverage from every shard's charts;\n"
      "`seconds` the slowest shard's; each shard's figures under \"shards\", their CPU time in\n"
      "all under \"merge\"). Parts of different projects or settings, or a shard missing or\n"
      "repeated: exit 2 naming it. All or nothing: on an error DIR is left as it was.\n\n"
      "  --quiet   no summary line on stderr";
  spec.min_positional = 1;
  spec.max_positional = 100000;
  spec.options = {"--out"};
  spec.switches = {"--quiet"};
  spec.required = {"--out"};
  return spec;
}

}  // namespace

int RunVerbMerge(const CommandArgs& argv) {
  const ArgSpec spec = MergeSpec();
  Args args;
  if (int code = ParseVerbArgs("merge", argv, spec, &args); code >= 0) return code;
  MergeResult result;
  if (Status s = MergeParts(args.positional, args.Get("--out"), &result); !s.ok()) return Fail(s);
  if (!args.Switch("--quiet"))
    std::fprintf(stderr,
                 "fresco merge: %d shards, %d pages -> %s (shards' CPU %.1f s in all; slowest "
                 "shard %.2f s, mean %.2f s)\n",
                 result.shards, result.textures, args.Get("--out").c_str(), result.cpu_seconds,
                 result.largest_shard_seconds, result.mean_shard_seconds);
  return kExitOk;
}

}  // namespace fresco
