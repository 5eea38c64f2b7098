// robodamp's DDS message types by their plain names. The IDL (dds/robodamp.idl) declares them in ROS 2's
// form (robodamp::msg::dds_::Telemetry_ ...), which is what goes on the wire; the code uses these aliases.
#pragma once

#include <cstdint>

#include "robodamp.h"
#include "robodampPubSubTypes.h"

namespace robodamp::msg {

using Telemetry = dds_::Telemetry_;
using Status = dds_::Status_;
using ParameterRequest = dds_::ParameterRequest_;
using ParameterReply = dds_::ParameterReply_;
using Machining = dds_::Machining_;
using Advice = dds_::Advice_;
using Spectrum = dds_::Spectrum_;
using Lobes = dds_::Lobes_;
using TelemetryPubSubType = dds_::Telemetry_PubSubType;
using StatusPubSubType = dds_::Status_PubSubType;
using ParameterRequestPubSubType = dds_::ParameterRequest_PubSubType;
using ParameterReplyPubSubType = dds_::ParameterReply_PubSubType;
using MachiningPubSubType = dds_::Machining_PubSubType;
using AdvicePubSubType = dds_::Advice_PubSubType;
using SpectrumPubSubType = dds_::Spectrum_PubSubType;
using LobesPubSubType = dds_::Lobes_PubSubType;
using RequestKind = std::uint8_t;  // ParameterRequest_.kind
using dds_::ENABLE;
using dds_::RESET_FAULT;
using dds_::SELECT_PARAMETER_SET;
using dds_::SET_GAIN;
using dds_::SET_SPINDLE_RPM;

}  // namespace robodamp::msg

namespace robodamp::msg {
// ROS 2's sensor_msgs/msg/JointState (dds.joint_states).
using JointState = ::sensor_msgs::msg::dds_::JointState_;
using JointStatePubSubType = ::sensor_msgs::msg::dds_::JointState_PubSubType;
// ROS 2's trajectory_msgs/msg/JointTrajectory (dds.path_ahead).
using JointTrajectory = ::trajectory_msgs::msg::dds_::JointTrajectory_;
using JointTrajectoryPoint = ::trajectory_msgs::msg::dds_::JointTrajectoryPoint_;
using JointTrajectoryPubSubType = ::trajectory_msgs::msg::dds_::JointTrajectory_PubSubType;
}  // namespace robodamp::msg
