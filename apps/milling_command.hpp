// `robodamp lobes` and `robodamp sle`: what a cut buys with and without active damping, as a table, JSON
// and a plot (REFERENCE.md sections 2 and 3).
#pragma once

#include <string>
#include <vector>

namespace robodamp::apps {

struct MillingOptions {
  std::string config_path;
  std::string structure;          // empty: the configuration's choice
  bool json{false};
  std::string plot_path;          // PNG
  bool damped{false};             // also with the controller's loop closed, overlaid
  std::vector<double> rpm;        // lobes: extra speeds for the direct test
  std::string controller_path;    // replaces every controller part's damping configuration
};

// Exit status: 0 done, 1 plot failed, 2 configuration error.
int run_lobes(const MillingOptions& options);
int run_sle(const MillingOptions& options);

}  // namespace robodamp::apps
