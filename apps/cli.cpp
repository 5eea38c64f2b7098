#include "apps/cli.hpp"

#include <algorithm>
#include <iostream>

#include "rt/version.hpp"

namespace robodamp::apps {

std::string version_text() {
  std::string text = std::string("robodamp ") + rt::version() + " (commit " + rt::git_commit() + ")\nbuilt against:";
  const std::string deps = ROBODAMP_DEPENDENCY_VERSIONS;
  for (std::size_t start = 0; start <= deps.size();) {
    const std::size_t end = std::min(deps.find('|', start), deps.size());
    text += "\n  " + deps.substr(start, end - start);
    start = end + 1;
  }
  return text;
}

int dispatch(int argc, const char* const* argv) {
  CLI::App app{"robodamp: real-time active vibration damping for robotic milling"};
  app.require_subcommand(1);
  Registry r(app);
  for (auto reg : {register_bench,    register_analyze, register_filters,    register_check_config, register_run,
                   register_replay,   register_csv,     register_lobes,      register_sle,          register_cut,
                   register_identify, register_measure, register_commission, register_pose,         register_tune,
                   register_schedule, register_chatter, register_plant,      register_monitor,      register_request,
                   register_dashboard})
    reg(r);
  app.set_version_flag(
      "--version", [] { return version_text(); }, "robodamp's version and the dependencies it was built against");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "robodamp: " << e.what()
              << " (robodamp --help lists the commands, robodamp COMMAND --help the options)\n";
    return 2;
  }
  return r.run_parsed();
}

}  // namespace robodamp::apps
