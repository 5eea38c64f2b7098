// Parameter requests from outside the loop (DDS): checked against the running supervisor with the
// configuration's own wording (key, value, unit, allowed range), turned into the operator command that
// the loop applies at its next tick. Pure: no I/O, nothing queued here.
#pragma once

#include "config/config.hpp"
#include "dds/bridge.hpp"
#include "rt/supervisor.hpp"

namespace robodamp::runtime {

struct CheckedRequest {
  dds::Decision decision;       // accepted, or refused with the reason
  rt::OperatorCommand command;  // what to post when accepted
};

[[nodiscard]] CheckedRequest check_request(const rt::Supervisor& sup, const config::Config& cfg, dds::RequestKind kind,
                                           double value);

}  // namespace robodamp::runtime
