#include "runtime/lifecycle.hpp"

#include <exception>

#include "config/config.hpp"

namespace robodamp::runtime {

const char* to_string(LifecycleState s) {
  switch (s) {
    case LifecycleState::kUnconfigured:
      return "unconfigured";
    case LifecycleState::kInactive:
      return "inactive";
    case LifecycleState::kActive:
      return "active";
  }
  return "?";
}

Status Component::transition(LifecycleState from, LifecycleState to, const char* verb, Status (Component::*hook)()) {
  if (state_ != from)
    return {StatusKind::kWrongState,
            name_ + ": cannot " + verb + " while " + to_string(state_) + " (only while " + to_string(from) + ")"};
  Status s;
  try {
    s = (this->*hook)();
  } catch (const config::ConfigError& e) {
    s = {StatusKind::kConfigError, e.what()};
  } catch (const std::exception& e) {
    s = {StatusKind::kDeviceError, name_ + ": " + e.what()};
  }
  if (s.ok()) state_ = to;
  return s;
}

Status Component::configure() {
  return transition(LifecycleState::kUnconfigured, LifecycleState::kInactive, "configure", &Component::on_configure);
}
Status Component::activate() {
  return transition(LifecycleState::kInactive, LifecycleState::kActive, "activate", &Component::on_activate);
}
Status Component::deactivate() {
  // A deactivation always ends inactive: the safe state is not optional.
  Status s = transition(LifecycleState::kActive, LifecycleState::kInactive, "deactivate", &Component::on_deactivate);
  if (s.kind != StatusKind::kWrongState) state_ = LifecycleState::kInactive;
  return s;
}
Status Component::cleanup() {
  return transition(LifecycleState::kInactive, LifecycleState::kUnconfigured, "cleanup", &Component::on_cleanup);
}

}  // namespace robodamp::runtime
