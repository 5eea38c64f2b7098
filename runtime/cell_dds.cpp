// The cell on DDS: what the bridge publishes and whom its requests and joint states reach (runtime/cell.hpp).
#include <algorithm>

#include "control/controller.hpp"
#include "runtime/cell.hpp"

namespace robodamp::runtime {

dds::BridgeSources Cell::bridge_sources() {
  return dds::BridgeSources{
      config::cell_name(cfg_.cell),
      backend_name_,
      [this] { return supervisor_->active_parameter_set(); },
      [this] { return std::min(supervisor_->gain_limit_ns_per_m(), control::kMaxGainNsPerM); },
      [this](dds::RequestKind k, double v) { return handle_request(k, v); },
      cfg_.spindle.job.empty() ? std::function<dds::MachiningSample()>{} : [this] { return machining_->sample(); },
      cfg_.spindle.job.empty() ? std::function<std::optional<dds::AdviceSample>()>{}
                               : [this]() -> std::optional<dds::AdviceSample> {
        const auto a = machining_->advice();
        return a ? std::optional(to_sample(*a)) : std::nullopt;
      },
      [this] { return spectrum_at_pose(); },
      cfg_.spindle.job.empty() ? std::function<std::optional<dds::LobesSample>()>{}
                               : [this] { return machining_->lobes(); },
      cfg_.controller.gain_ramp_s,
      [this] { return supervisor_->parameter_sets().size(); },
      cfg_.spindle.rpm_max,
      joint_pose_ ? std::function<void(const std::vector<std::string>&, const std::vector<double>&)>(
                        [this](const std::vector<std::string>& n, const std::vector<double>& q) {
                          joint_pose_->on_message(n, q);
                        })
                  : nullptr,
      joint_pose_ ? std::function<void()>([this] { joint_pose_->check(); }) : nullptr,
      path_ahead_ ? std::function<void(const std::vector<std::string>&, const std::vector<dds::TrajectoryPoint>&)>(
                        [this](const std::vector<std::string>& n, const std::vector<dds::TrajectoryPoint>& p) {
                          path_ahead_->on_message(n, p);
                        })
                  : nullptr};
}

}  // namespace robodamp::runtime
