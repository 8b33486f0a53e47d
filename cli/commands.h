// The verbs of the `rdm` command-line tool. Each takes the arguments after the verb and
// returns the process exit code (0 ok, 1 failure, 2 usage error).
#pragma once

#include <string>
#include <vector>

namespace rdm::cli {

using Args = std::vector<std::string>;

int cmdBake(const Args& args);
int cmdRender(const Args& args);
int cmdScene(const Args& args);
int cmdFlip(const Args& args);
int cmdMerge(const Args& args);
int cmdDiff(const Args& args);
int cmdServe(const Args& args);   // cmd_serve.cpp
int cmdSubmit(const Args& args);  // cmd_client.cpp
int cmdPatch(const Args& args);
int cmdStatus(const Args& args);
int cmdFetch(const Args& args);
int cmdCancel(const Args& args);
int cmdPreview(const Args& args);
int cmdImport(const Args& args);

}  // namespace rdm::cli
