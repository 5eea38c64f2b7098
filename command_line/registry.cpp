#include "command_line/registry.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "config/config.hpp"
#include "config/number_text.hpp"

namespace robodamp::command_line {

using config::parse_number;

CLI::App* Registry::add(const std::string& name, const std::string& description, std::function<int()> handler) {
  CLI::App* sub = app_.add_subcommand(name, description);
  handlers_.emplace_back(sub, std::move(handler));
  return sub;
}

CLI::Option* Registry::text_option(CLI::App* sub, const std::string& flag, const std::string& help, bool many) {
  texts_.emplace_back();
  std::vector<std::string>& texts = texts_.back();
  CLI::Option* opt = sub->add_option(flag, texts, help);
  opt->type_name("NUMBER");
  if (!many) opt->expected(1);
  return opt;
}

namespace {
std::string first_name(const CLI::Option* opt) {
  return opt->get_name(false, true).substr(0, opt->get_name(false, true).find(','));
}
}  // namespace

CLI::Option* Registry::scalar(CLI::App* sub, const std::string& flag, const config::Range& range, bool whole,
                              const std::string& help, std::function<void(double)> assign) {
  CLI::Option* opt = text_option(sub, flag, help + " [" + config::describe_range(range) + "]", false);
  const std::vector<std::string>& texts = texts_.back();
  checks_.push_back({sub, [opt, &texts, range, whole, assign = std::move(assign)]() -> std::optional<std::string> {
                       if (texts.empty()) return std::nullopt;
                       double v = 0.0;
                       if (auto p = parse_number(first_name(opt), texts.back(), range, whole, v)) return p;
                       assign(v);
                       return std::nullopt;
                     }});
  return opt;
}

CLI::Option* Registry::number(CLI::App* sub, const std::string& flag, double& target, const config::Range& range,
                              const std::string& help) {
  return scalar(sub, flag, range, false, help, [&target](double v) { target = v; })
      ->default_str(config::format_number(target));
}

CLI::Option* Registry::number(CLI::App* sub, const std::string& flag, std::optional<double>& target,
                              const config::Range& range, const std::string& help) {
  return scalar(sub, flag, range, false, help, [&target](double v) { target = v; });
}

CLI::Option* Registry::whole_number(CLI::App* sub, const std::string& flag, int& target, const config::Range& range,
                                    const std::string& help) {
  return scalar(sub, flag, range, true, help, [&target](double v) { target = static_cast<int>(v); })
      ->default_str(std::to_string(target));
}

CLI::Option* Registry::whole_number(CLI::App* sub, const std::string& flag, std::optional<int>& target,
                                    const config::Range& range, const std::string& help) {
  return scalar(sub, flag, range, true, help, [&target](double v) { target = static_cast<int>(v); });
}

CLI::Option* Registry::numbers(CLI::App* sub, const std::string& flag, std::vector<double>& target,
                               const config::Range& range, const std::string& help) {
  CLI::Option* opt = text_option(sub, flag, help + " [" + config::describe_range(range) + "]", true);
  const std::vector<std::string>& texts = texts_.back();
  checks_.push_back({sub, [opt, &texts, &target, range]() -> std::optional<std::string> {
                       // The values given replace a default (pose frf's band was 2-60 Hz whatever --band-hz said).
                       if (!texts.empty()) target.clear();
                       for (const auto& t : texts) {
                         double v = 0.0;
                         if (auto p = parse_number(first_name(opt), t, range, false, v)) return p;
                         target.push_back(v);
                       }
                       return std::nullopt;
                     }});
  return opt;
}

std::vector<std::string> Registry::number_problems(const CLI::App* sub) const {
  std::vector<std::string> out;
  for (const auto& c : checks_)
    if (c.sub == sub)
      if (auto p = c.problem()) out.push_back(*p);
  return out;
}

namespace {

int g_json_fd = -1;  // the real stdout while --json prints there (the command's text goes to stderr)

// While --json prints on stdout: file descriptor 1 is stderr for the command (iostreams and stdio alike),
// and the JSON goes to the saved stdout.
class StdoutForJson {
 public:
  explicit StdoutForJson(bool on) {
    if (!on) return;
    std::cout.flush();
    std::fflush(stdout);
    g_json_fd = ::dup(1);
    if (g_json_fd >= 0) (void)::dup2(2, 1);
  }
  ~StdoutForJson() {
    if (g_json_fd < 0) return;
    std::cout.flush();
    std::fflush(stdout);
    (void)::dup2(g_json_fd, 1);
    ::close(g_json_fd);
    g_json_fd = -1;
  }
  StdoutForJson(const StdoutForJson&) = delete;
  StdoutForJson& operator=(const StdoutForJson&) = delete;
};

}  // namespace

bool emit_json(const JsonOut& out, const std::string& text, const std::string& command) {
  if (!out.given) return true;
  if (out.to_stdout()) {
    const std::string line = text + '\n';
    const int fd = g_json_fd >= 0 ? g_json_fd : 1;
    std::cout.flush();
    std::fflush(stdout);
    for (std::size_t done = 0; done < line.size();) {
      const ssize_t n = ::write(fd, line.data() + done, line.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        std::cerr << "robodamp " << command << ": --json: cannot write to stdout\n";
        return false;
      }
      done += static_cast<std::size_t>(n);
    }
    return true;
  }
  std::ofstream f(out.path);
  f << text << '\n';
  f.close();
  if (!f) {
    std::cerr << "robodamp " << command << ": --json " << out.path << ": cannot write\n";
    return false;
  }
  return true;
}

CLI::Option* Registry::json(CLI::App* sub, JsonOut& target, const std::string& what) {
  CLI::Option* o = sub->add_option("--json", target.path,
                                   what +
                                       ": --json FILE writes it to FILE; --json alone or --json - prints it on "
                                       "stdout instead of the text (docs/cli.md)")
                       ->expected(0, 1)
                       ->type_name("[FILE]");
  json_.emplace_back(o, &target);
  return o;
}

CLI::Option* Registry::plot_dir(CLI::App* sub, std::string& target, const std::string& what) {
  return sub->add_option("--plot-dir", target, "Write " + what + " (PNG) into this directory")->type_name("DIR");
}

CLI::Option* Registry::deprecated(CLI::Option* option, const std::string& replacement) {
  option->description(option->get_description() + " (deprecated, kept for one release: use " + replacement + ")");
  deprecated_.emplace_back(option, replacement);
  return option;
}

CLI::Option* Registry::renamed(CLI::Option* now, const std::string& value, CLI::Option* old, const std::string& why) {
  deprecated(old, now->get_name() + " " + value + " (" + why + ")");
  now->excludes(old);
  return now;
}

CLI::Option* Registry::job(CLI::App* sub, std::string& target) {
  return renamed(sub->add_option("--job", target, "Milling job (YAML, config/milling/)")->check(CLI::ExistingFile),
                 "JOB", sub->add_option("--config", target, "The milling job, as --job")->check(CLI::ExistingFile),
                 "--config is the cell's configuration in every other command");
}

int Registry::run_parsed() const {
  for (const auto& [sub, handler] : handlers_) {
    if (!sub->parsed()) continue;
    const auto problems = number_problems(sub);
    for (const auto& p : problems) std::cerr << "robodamp " << sub->get_name() << ": " << p << '\n';
    if (!problems.empty()) return 2;
    bool json_to_stdout = false;
    for (const auto& [opt, out] : json_) {
      out->given = opt->count() > 0;
      json_to_stdout = json_to_stdout || out->to_stdout();
    }
    for (const auto& [opt, replacement] : deprecated_)
      if (opt->count() > 0)
        std::cerr << "robodamp " << sub->get_name() << ": " << opt->get_name()
                  << " is deprecated (kept for one release): use " << replacement << '\n';
    const StdoutForJson redirect(json_to_stdout);
    try {
      return handler();
    } catch (const config::ConfigError& e) {  // a handler's own configuration checks
      std::cerr << e.what() << '\n';
      return 2;
    } catch (const std::exception& e) {  // a device, a file or a transport that failed: never a crash
      std::cerr << "robodamp " << sub->get_name() << ": " << e.what() << '\n';
      return 1;
    }
  }
  return 2;
}

}  // namespace robodamp::command_line
