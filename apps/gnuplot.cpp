#include "apps/gnuplot.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <unistd.h>

namespace robodamp::apps {

std::string run_gnuplot(const std::string& script, const std::string& data, const std::string& png_path) {
  namespace fs = std::filesystem;
  char tmpl[] = "/tmp/robodamp-plot-XXXXXX";
  const int fd = mkstemp(tmpl);
  if (fd < 0) return "cannot create a temporary data file";
  close(fd);
  const std::string data_path = tmpl;
  { std::ofstream(data_path) << data; }
  std::error_code ec;
  fs::remove(png_path, ec);
  FILE* gp = popen("gnuplot 2>&1", "w");
  if (gp == nullptr) {
    fs::remove(data_path, ec);
    return "cannot start gnuplot (apt-get install gnuplot-nox)";
  }
  std::fprintf(gp, "DATA = '%s'\nset terminal pngcairo noenhanced size 1200,900 font ',10'\nset output '%s'\n%s\nset output\n",
               data_path.c_str(), png_path.c_str(), script.c_str());
  const int rc = pclose(gp);
  fs::remove(data_path, ec);
  if (rc != 0) return "gnuplot exited with status " + std::to_string(rc);
  if (!fs::exists(png_path) || fs::file_size(png_path) == 0) return "gnuplot wrote no image to " + png_path;
  return {};
}

int print_report(const std::string& json_text, bool json, const std::string& table, const std::string& plot_target,
                 const std::function<std::string()>& plot, const std::string& wrote) {
  if (json)
    std::cout << json_text << '\n';
  else
    std::cout << table;
  if (!plot_target.empty()) {
    if (const std::string err = plot(); !err.empty()) {
      std::cerr << "plot: " << err << '\n';
      return 1;
    }
    (json ? std::cerr : std::cout) << "wrote " << wrote << '\n';
  }
  return 0;
}

}  // namespace robodamp::apps
