#include <cstdio>
#include <cstring>
#include <string>

#include "cli_app.h"
#include "commands.h"

namespace {

struct Verb {
  const char* name;
  int (*run)(const rdm::cli::Args&);
  const char* summary;
};

constexpr Verb kVerbs[] = {
    {"bake", rdm::cli::cmdBake, "bake the RDM atlas of a scene (Ctrl-C stops cleanly)"},
    {"render", rdm::cli::cmdRender, "path-trace a reference image (.exr or .png)"},
    {"scene", rdm::cli::cmdScene, "export a built-in scene as JSON, or validate a scene file"},
    {"flip", rdm::cli::cmdFlip, "FLIP error between a reference and a test image"},
    {"merge", rdm::cli::cmdMerge, "merge shard outputs of `rdm bake --shard` into one atlas"},
    {"diff", rdm::cli::cmdDiff, "compare two atlases RDM by RDM (exit 1 when they differ)"},
    {"import", rdm::cli::cmdImport, "import a MagicaVoxel .vox file as a scene JSON"},
    {"preview", rdm::cli::cmdPreview, "PNG of an EXR: colour, --depth, or the bake's --noise"},
    {"serve", rdm::cli::cmdServe, "run the bake daemon (HTTP API, job queue)"},
    {"submit", rdm::cli::cmdSubmit, "upload a scene to a daemon and submit a bake"},
    {"patch", rdm::cli::cmdPatch, "change a scene on a daemon by one PATCH of the difference"},
    {"status", rdm::cli::cmdStatus, "show a daemon job's state, progress and ETA"},
    {"fetch", rdm::cli::cmdFetch, "wait for a daemon job and download its atlas"},
    {"cancel", rdm::cli::cmdCancel, "cancel a daemon job"},
};

void printUsage(std::FILE* to) {
  std::fprintf(to,
               "usage: rdm <verb> [options]   (rdm <verb> --help lists every option with its "
               "default)\n       rdm --version\n\nverbs:\n");
  for (const Verb& verb : kVerbs) std::fprintf(to, "  %-8s %s\n", verb.name, verb.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    printUsage(stderr);
    return 2;
  }
  const std::string first = argv[1];
  if (first == "--help" || first == "-h" || first == "help") {
    printUsage(stdout);
    return 0;
  }
  if (first == "--version" || first == "-V") {
    std::printf("%s\n", rdm::cli::versionText().c_str());
    return 0;
  }
  rdm::cli::Args args(argv + 2, argv + argc);
  for (const Verb& verb : kVerbs) {
    if (first == verb.name) return verb.run(args);
  }
  std::fprintf(stderr, "rdm: unknown %s '%s'\n", first[0] == '-' ? "option" : "verb", argv[1]);
  printUsage(stderr);
  return 2;
}
