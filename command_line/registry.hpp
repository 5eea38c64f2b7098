// The command line's machinery, shared by every command in apps/: the subcommand registry with strict,
// range-checked numbers (each checked after parsing in the configuration's wording, "--rpm = 0 rpm is out of
// range: allowed 1 <= value <= 200000 rpm"), the one --json [FILE] output, --plot-dir, and the deprecated
// spellings kept for one release (docs/cli.md). A bad command line exits with status 2 and a message, before
// anything runs. Off the real-time path.
#pragma once

#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "config/number_range.hpp"

namespace robodamp::command_line {

// The one --json of every command (docs/cli.md): `--json FILE` writes the JSON to FILE and the command
// prints its text as usual; `--json` alone or `--json -` prints the JSON on stdout, and then stdout
// carries nothing else (the command's text goes to stderr).
struct JsonOut {
  std::string path;
  bool given{false};  // set after parsing
  [[nodiscard]] bool to_stdout() const { return given && (path.empty() || path == "-"); }
  [[nodiscard]] bool to_file() const { return given && !to_stdout(); }
};
// Writes the JSON where --json asked (nothing when it was not given); false, with the reason on stderr,
// when the file cannot be written.
[[nodiscard]] bool emit_json(const JsonOut& out, const std::string& text, const std::string& command);

class Registry {
 public:
  explicit Registry(CLI::App& app) : app_(app) {}

  // A subcommand and what runs when it is given (its exit status).
  CLI::App* add(const std::string& name, const std::string& description, std::function<int()> handler);

  // Numbers, parsed strictly (no trailing text, finite) and range-checked after parsing; the target keeps
  // its default when the option is absent.
  CLI::Option* number(CLI::App* sub, const std::string& flag, double& target, const config::Range& range,
                      const std::string& help);
  CLI::Option* number(CLI::App* sub, const std::string& flag, std::optional<double>& target, const config::Range& range,
                      const std::string& help);
  CLI::Option* whole_number(CLI::App* sub, const std::string& flag, int& target, const config::Range& range,
                            const std::string& help);
  CLI::Option* whole_number(CLI::App* sub, const std::string& flag, std::optional<int>& target,
                            const config::Range& range, const std::string& help);
  CLI::Option* numbers(CLI::App* sub, const std::string& flag, std::vector<double>& target, const config::Range& range,
                       const std::string& help);
  // The --json [FILE] option (JsonOut); `what` says what the JSON holds.
  CLI::Option* json(CLI::App* sub, JsonOut& target, const std::string& what);
  // The --plot-dir DIR option: where the command writes its plots (PNG), `what` says which.
  CLI::Option* plot_dir(CLI::App* sub, std::string& target, const std::string& what);
  // An old spelling kept for one release: still works, says on stderr what replaces it.
  CLI::Option* deprecated(CLI::Option* option, const std::string& replacement);
  // An option renamed: `now` (its value shown as `value`, e.g. FILE) and the `old` spelling of the same value,
  // deprecated for one release (`why` the old name went, in the deprecation note); giving both is refused.
  // Returns `now`.
  CLI::Option* renamed(CLI::Option* now, const std::string& value, CLI::Option* old, const std::string& why);
  // --job FILE, the milling job (config/milling/), as every command names it; and the old --config JOB of
  // lobes, sle and cut, deprecated: --config is the cell everywhere else (docs/cli.md).
  CLI::Option* job(CLI::App* sub, std::string& target);

  // After parsing: the problems of the numbers given to `sub`, each in the configuration's wording.
  [[nodiscard]] std::vector<std::string> number_problems(const CLI::App* sub) const;
  // The handler of the subcommand that was given.
  [[nodiscard]] int run_parsed() const;

 private:
  struct Check {
    const CLI::App* sub;
    std::function<std::optional<std::string>()> problem;  // parses the text into its target
  };
  CLI::Option* text_option(CLI::App* sub, const std::string& flag, const std::string& help, bool many);
  CLI::Option* scalar(CLI::App* sub, const std::string& flag, const config::Range& range, bool whole,
                      const std::string& help, std::function<void(double)> assign);
  CLI::App& app_;
  std::vector<std::pair<CLI::App*, std::function<int()>>> handlers_;
  std::vector<std::pair<CLI::Option*, JsonOut*>> json_;
  std::vector<std::pair<CLI::Option*, std::string>> deprecated_;
  std::vector<Check> checks_;
  std::deque<std::vector<std::string>> texts_;  // stable addresses for CLI11 to fill
};

}  // namespace robodamp::command_line
