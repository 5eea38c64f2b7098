// The lifecycle every part of a cell goes through, after ros2_control's hardware components (the
// managed-node states): Unconfigured --configure--> Inactive --activate--> Active --deactivate-->
// Inactive --cleanup--> Unconfigured. configure() opens devices and may allocate; activate() starts
// them (threads, polling, flushing queues); deactivate() brings them to their safe state; cleanup()
// releases them. A transition from the wrong state is refused (kWrongState) and changes nothing; a
// failed transition leaves the component in the state it started from. None of this is on the real-time
// path: the loop thread only calls the rt/io.hpp interfaces the active components expose.
#pragma once

#include <cstdint>
#include <string>

namespace robodamp::runtime {

enum class LifecycleState : std::uint8_t { kUnconfigured, kInactive, kActive };
[[nodiscard]] const char* to_string(LifecycleState s);

enum class StatusKind : std::uint8_t {
  kOk,
  kConfigError,  // the configuration (or a file it names) is wrong: exit status 2
  kDeviceError,  // a device could not be opened or started: exit status 1
  kWrongState,   // the transition is not allowed from the current state
};

struct [[nodiscard]] Status {
  StatusKind kind{StatusKind::kOk};
  std::string message;
  [[nodiscard]] bool ok() const noexcept { return kind == StatusKind::kOk; }
};

class Component {
 public:
  explicit Component(std::string name) : name_(std::move(name)) {}
  virtual ~Component() = default;
  Component(const Component&) = delete;
  Component& operator=(const Component&) = delete;

  Status configure();
  Status activate();
  Status deactivate();
  Status cleanup();

  [[nodiscard]] LifecycleState state() const noexcept { return state_; }
  [[nodiscard]] const std::string& name() const noexcept { return name_; }

 protected:
  // Hooks: throw config::ConfigError for a configuration problem, any other exception for a device
  // problem, or return a Status; the base class turns either into the transition's Status.
  virtual Status on_configure() = 0;
  virtual Status on_activate() { return {}; }
  virtual Status on_deactivate() { return {}; }
  virtual Status on_cleanup() { return {}; }

 private:
  Status transition(LifecycleState from, LifecycleState to, const char* verb, Status (Component::*hook)());
  std::string name_;
  LifecycleState state_{LifecycleState::kUnconfigured};
};

}  // namespace robodamp::runtime
