#include "cli_app.h"

#include <cstdio>

#include "number_checks.h"
#include "rdm/base/build_id.h"

namespace rdm::cli {

VerbApp::VerbApp(const std::string& verb, const std::string& description)
    : CLI::App(description, "rdm " + verb) {
  option_defaults()->always_capture_default();
  allow_extras();  // reported by parseArgs as "unknown option", with the verb's name
  get_formatter()->column_width(34);
}

std::optional<int> parseArgs(CLI::App& app, const Args& args) {
  const std::string verb = app.get_name();
  wordNumberChecks(app);
  try {
    app.parse(std::vector<std::string>(args.rbegin(), args.rend()));
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s\n(%s --help lists every option)\n", verb.c_str(), e.what(),
                 verb.c_str());
    return 2;
  }
  for (const std::string& extra : app.remaining()) {
    const bool option = extra.size() > 1 && extra[0] == '-';
    std::fprintf(stderr, "%s: %s %s\n(%s --help lists every option)\n", verb.c_str(),
                 option ? "unknown option" : "unexpected argument", extra.c_str(), verb.c_str());
    return 2;
  }
  return std::nullopt;
}

int fail(const std::string& verb, const std::string& message, int code) {
  std::fprintf(stderr, "rdm %s: %s\n", verb.c_str(), message.c_str());
  return code;
}

std::string versionText() {
  return "rdm " + buildId();
}

}  // namespace rdm::cli
