#include "plot/gnuplot.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>

#include <openssl/evp.h>

namespace robodamp::plot {

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
  std::fprintf(
      gp, "DATA = '%s'\nset terminal pngcairo noenhanced size 1200,900 font ',10'\nset output '%s'\n%s\nset output\n",
      data_path.c_str(), png_path.c_str(), script.c_str());
  const int rc = pclose(gp);
  fs::remove(data_path, ec);
  if (rc != 0) return "gnuplot exited with status " + std::to_string(rc);
  if (!fs::exists(png_path) || fs::file_size(png_path) == 0) return "gnuplot wrote no image to " + png_path;
  return {};
}

std::string png_data_uri(const std::string& png_path) {
  std::ifstream in(png_path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) return {};
  if (bytes.empty()) return {};
  std::string out(4 * ((bytes.size() + 2) / 3) + 1, '\0');
  const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()),
                                reinterpret_cast<const unsigned char*>(bytes.data()), static_cast<int>(bytes.size()));
  out.resize(static_cast<std::size_t>(n));
  return "data:image/png;base64," + out;
}

std::string num(double v) {
  if (!std::isfinite(v)) return "NaN";
  char b[32];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

}  // namespace robodamp::plot
