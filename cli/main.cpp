#include <cstdio>
#include <cstring>
#include <string>

#include "commands.h"

namespace {

struct Verb {
  const char* name;
  int (*run)(const rdm::cli::Args&);
  const char* summary;
};

constexpr Verb kVerbs[] = {
    {"bake", rdm::cli::cmdBake, "bake the RDM atlas of a scene"},
    {"render", rdm::cli::cmdRender, "path-trace a reference image through a scene camera"},
    {"scene", rdm::cli::cmdScene, "export a built-in scene as JSON, or validate a scene file"},
    {"flip", rdm::cli::cmdFlip, "FLIP error between a reference and a test image"},
    {"merge", rdm::cli::cmdMerge, "merge shard outputs of `rdm bake --shard` into one atlas"},
    {"import", rdm::cli::cmdImport, "import a MagicaVoxel .vox model as a scene JSON"},
    {"preview", rdm::cli::cmdPreview, "tone-mapped PNG of an EXR (atlas, RDM, render)"},
    {"serve", rdm::cli::cmdServe, "run the bake daemon (HTTP API, job queue)"},
    {"submit", rdm::cli::cmdSubmit, "upload a scene to a daemon and submit a bake"},
    {"status", rdm::cli::cmdStatus, "show a daemon job's status"},
    {"fetch", rdm::cli::cmdFetch, "wait for a daemon job and download its atlas"},
};

void printUsage() {
  std::fprintf(stderr, "usage: rdm <verb> [options]   (rdm <verb> --help for details)\n\nverbs:\n");
  for (const Verb& verb : kVerbs) std::fprintf(stderr, "  %-8s %s\n", verb.name, verb.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    printUsage();
    return argc < 2 ? 2 : 0;
  }
  rdm::cli::Args args(argv + 2, argv + argc);
  for (const Verb& verb : kVerbs) {
    if (std::string(argv[1]) == verb.name) return verb.run(args);
  }
  std::fprintf(stderr, "rdm: unknown verb '%s'\n", argv[1]);
  printUsage();
  return 2;
}
