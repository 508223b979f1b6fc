#include "app/suggest.h"

#include <algorithm>

namespace armfault {

namespace {

std::vector<std::string> OptionNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* o : app.get_options()) {
    for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : o->get_snames()) names.push_back("-" + n);
  }
  return names;
}

}  // namespace

std::string SuggestForParseError(CLI::App& app, int argc, char** argv) {
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
  CLI::App* sub = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.empty() || arg[0] == '-') continue;
    if (std::find(commands.begin(), commands.end(), arg) == commands.end()) {
      const std::string near = NearestWord(arg, commands);
      return "armfault: unknown command \"" + arg + "\"" + (near.empty() ? "" : "; did you mean \"" + near + "\"?");
    }
    sub = app.get_subcommand(arg);
    break;
  }
  if (!sub) return "";
  std::vector<std::string> known = OptionNames(*sub);
  for (const std::string& n : OptionNames(app)) known.push_back(n);
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-' || arg == "--") continue;
    arg = arg.substr(0, arg.find('='));
    if (std::find(known.begin(), known.end(), arg) != known.end()) continue;
    const std::string near = NearestWord(arg, known);
    return "armfault " + sub->get_name() + ": unknown option " + arg + (near.empty() ? "" : "; did you mean " + near + "?");
  }
  return "";
}

}  // namespace armfault
