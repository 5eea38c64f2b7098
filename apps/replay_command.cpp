// `robodamp replay FILE`: a recording's inputs through the same supervisor and controller; every
// command, state and trip checked bit for bit.
#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "rt/recording.hpp"

namespace robodamp::apps {

namespace {

// 0 bit-exact, 1 mismatches, 2 unreadable recording.
int run_replay(const std::string& path) {
  try {
    const rt::Recording r = rt::read_recording(path);
    const rt::ReplayResult res = rt::replay(r);
    std::cout << path << ": " << res.frames << " frames (" << r.header.value("clock", "?") << " clock, "
              << r.header.value("rate_hz", 0.0) << " Hz, robodamp " << r.header.value("robodamp_version", "?") << " "
              << r.header.value("git_commit", "?") << ")\n";
    if (r.trailing_bytes > 0)
      std::cout << "  note: " << r.trailing_bytes << " trailing bytes of a partial frame ignored\n";
    std::cout << "  replayed through the same supervisor and controller: final state " << res.final_state << ", trip "
              << res.final_trip << '\n';
    if (res.mismatches == 0) {
      std::cout << "  commands reproduced bit for bit\n";
      return 0;
    }
    char b[200];
    std::snprintf(b, sizeof b, "  %llu frames differ; first at tick %llu: recorded %.17g V, replayed %.17g V\n",
                  static_cast<unsigned long long>(res.mismatches),
                  static_cast<unsigned long long>(res.first_mismatch_tick), res.first_recorded_v, res.first_replayed_v);
    std::cout << b;
    return 1;
  } catch (const std::exception& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

}  // namespace

void register_replay(Registry& r) {
  auto path = std::make_shared<std::string>();
  CLI::App* sub =
      r.add("replay", "Feed a recording's inputs through the same controller; check the commands bit for bit",
            [path] { return run_replay(*path); });
  sub->add_option("file", *path, "Recording (from run --record)")->required()->check(CLI::ExistingFile);
}

}  // namespace robodamp::apps
