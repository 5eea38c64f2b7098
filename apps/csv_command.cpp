// `robodamp csv FILE [-o OUT]`: a recording as CSV, one row per tick.
#include <cstdio>
#include <iostream>
#include <memory>

#include "apps/cli.hpp"
#include "rt/recording.hpp"

namespace robodamp::apps {

namespace {

int run_csv(const std::string& path, const std::string& out_path) {
  try {
    const rt::Recording r = rt::read_recording(path);
    std::FILE* out = out_path.empty() || out_path == "-" ? stdout : std::fopen(out_path.c_str(), "w");
    if (out == nullptr) {
      std::cerr << "-o " << out_path << ": cannot open for writing\n";
      return 1;
    }
    rt::write_csv(r, out);
    const bool ok = std::ferror(out) == 0;
    if (out != stdout) std::fclose(out);
    if (!ok) {
      std::cerr << "-o " << out_path << ": write failed\n";
      return 1;
    }
    if (out != stdout) std::cout << "wrote " << r.frames.size() << " frames to " << out_path << '\n';
    return 0;
  } catch (const std::exception& e) {
    std::cerr << e.what() << '\n';
    return 2;
  }
}

}  // namespace

void register_csv(Registry& r) {
  auto path = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  CLI::App* sub = r.add("csv", "Export a recording as CSV", [path, out] { return run_csv(*path, *out); });
  sub->add_option("file", *path, "Recording (from run --record)")->required()->check(CLI::ExistingFile);
  sub->add_option("-o,--out", *out, "Output file (default: stdout)");
}

}  // namespace robodamp::apps
