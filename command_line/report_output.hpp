// A command's report as the user asked for it: the JSON where --json said, the table, then its plot (PNG),
// and where a command's one plot goes. Off the real-time path.
#pragma once

#include <functional>
#include <string>

#include "command_line/registry.hpp"

namespace robodamp::command_line {

// A report: the JSON where --json asked (registry.hpp), the table unless the JSON is on stdout, then the
// plot if a target is given: plot() returns the reason it failed or an empty string, and "wrote <what>"
// follows. Returns 0, or 1 when the JSON or the plot could not be written.
[[nodiscard]] int print_report(const std::string& json_text, const JsonOut& json, const std::string& command,
                               const std::string& table, const std::string& plot_target,
                               const std::function<std::string()>& plot, const std::string& wrote);

// Where a command's one plot goes: DIR/name with --plot-dir DIR (the directory made), else the deprecated
// --plot FILE (empty: no plot).
[[nodiscard]] std::string plot_file(const std::string& plot_dir, const std::string& legacy_file,
                                    const std::string& name);

}  // namespace robodamp::command_line
