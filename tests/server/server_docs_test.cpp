// docs/api.md against the daemon: the job status example lists exactly the fields a real
// job's status carries, at every level, so the reference cannot drift from the build.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "fresh_dir.h"
#include "rdm/base/file_util.h"
#include "server_process.h"
#include "test_scenes.h"

namespace rdm {
namespace {

using nlohmann::json;

// The first ```json block after the heading line that starts with `heading`.
json exampleAfter(const std::string& doc, const std::string& heading) {
  const size_t at = doc.find("\n" + heading);
  if (at == std::string::npos) return json();
  const size_t open = doc.find("```json\n", at);
  const size_t close = doc.find("\n```", open + 8);
  if (open == std::string::npos || close == std::string::npos) return json();
  return json::parse(doc.substr(open + 8, close - open - 8), nullptr, false);
}

// Dotted paths of every object key (not into arrays), e.g. "progress.fraction".
void keyPaths(const json& j, const std::string& prefix, std::set<std::string>& out) {
  if (!j.is_object()) return;
  for (const auto& [key, value] : j.items()) {
    out.insert(prefix + key);
    keyPaths(value, prefix + key + ".", out);
  }
}

std::set<std::string> keyPaths(const json& j) {
  std::set<std::string> out;
  keyPaths(j, "", out);
  return out;
}

// Keys whose value is null in one document and an object in the other are compared at
// their own level only (a running job's `noise` is null, a succeeded one's an object).
std::set<std::string> withoutNested(const std::set<std::string>& keys, const std::string& key) {
  std::set<std::string> out;
  for (const std::string& k : keys)
    if (k.rfind(key + ".", 0) != 0) out.insert(k);
  return out;
}

TEST(ServerDocs, ApiJobStatusExampleListsEveryFieldTheDaemonSends) {
  auto doc = readFileToString(std::string(RDM_TEST_DATA_DIR) + "/../../docs/api.md");
  ASSERT_TRUE(doc.ok()) << doc.error();
  const json example = exampleAfter(*doc, "### `GET /v1/jobs/{job}[?wait=S[&passes=N]]`");
  ASSERT_TRUE(example.is_object()) << "no parsable ```json example under the job status route";

  const std::string dir = test::freshTestDir("server_docs", "status");
  test::ServerProcess server(dir, {"--threads", "1"});
  auto c = test::connectClient(server);
  const std::string scene = test::must(c->uploadScene(test::tinyChess()), "upload")["id"];
  json real = test::waitSucceeded(*c, test::submit(*c, scene, json::object()));
  ASSERT_TRUE(real.contains("noise"));

  // `links` grows with the job's state (a succeeded job adds its result files'), and the
  // example is a running job: compared at the top level only.
  const auto compared = [](const json& j) {
    return withoutNested(withoutNested(keyPaths(j), "noise"), "links");
  };
  const std::set<std::string> documented = compared(example), sent = compared(real);
  for (const std::string& k : sent) EXPECT_TRUE(documented.count(k)) << "undocumented: " << k;
  for (const std::string& k : documented) EXPECT_TRUE(sent.count(k)) << "not sent: " << k;
}

}  // namespace
}  // namespace rdm
