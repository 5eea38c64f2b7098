#include "apps/gnuplot.hpp"

#include <iostream>

namespace robodamp::apps {

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
