#include "command_line/report_output.hpp"

#include <filesystem>
#include <iostream>

namespace robodamp::command_line {

int print_report(const std::string& json_text, const JsonOut& json, const std::string& command,
                 const std::string& table, const std::string& plot_target, const std::function<std::string()>& plot,
                 const std::string& wrote) {
  if (!emit_json(json, json_text, command)) return 1;
  if (!json.to_stdout()) std::cout << table;
  if (!plot_target.empty()) {
    if (const std::string err = plot(); !err.empty()) {
      std::cerr << "plot: " << err << '\n';
      return 1;
    }
    std::cout << "wrote " << wrote << '\n';  // stderr while the JSON is on stdout (registry.hpp)
  }
  return 0;
}

std::string plot_file(const std::string& plot_dir, const std::string& legacy_file, const std::string& name) {
  if (plot_dir.empty()) return legacy_file;
  std::error_code ec;
  std::filesystem::create_directories(plot_dir, ec);  // a failure shows when the plot is written
  return plot_dir + "/" + name;
}

}  // namespace robodamp::command_line
