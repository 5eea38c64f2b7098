// A Fast DDS participant with robodamp's eight topics and their QoS (docs/dds.md), shared by the loop's
// bridge, `robodamp monitor` and the tests. Off the real-time path.
//
//   DDS topic (ROS 2 topic)              type (ROS 2 form)                     reliability  durability       history
//   rt/robodamp/telemetry                robodamp::msg::dds_::Telemetry_        best effort  volatile         keep last 64
//   rt/robodamp/status                   robodamp::msg::dds_::Status_           reliable     transient local  keep last 1
//   rt/robodamp/parameter_request        robodamp::msg::dds_::ParameterRequest_ reliable     volatile         keep last 32
//   rt/robodamp/parameter_reply          robodamp::msg::dds_::ParameterReply_   reliable     volatile         keep last 32
//   rt/robodamp/machining                robodamp::msg::dds_::Machining_        reliable     transient local  keep last 1
//   rt/robodamp/advice                   robodamp::msg::dds_::Advice_           reliable     transient local  keep last 1
//   rt/robodamp/spectrum                 robodamp::msg::dds_::Spectrum_         reliable     transient local  keep last 1
//   rt/robodamp/lobes                    robodamp::msg::dds_::Lobes_            reliable     transient local  keep last 1
// (a reader keeps the last 256, 1024 of telemetry: every cell on the domain writes the same unkeyed topic)
// (ROS 2: /robodamp/telemetry with robodamp/msg/Telemetry, and so on; ros2/robodamp holds the .msg files.)
//
// Transports: default (Fast DDS built-ins: UDPv4 and shared memory), udp_loopback (UDPv4 on 127.0.0.1
// only, data sharing off) or shared_memory (SHM only).
//
// With a security section the participant authenticates (PKI-DH), is authorised by its signed
// permissions against the signed governance (Access-Permissions) and encrypts what the governance says
// (AES-GCM-GMAC): robodamp's governance (scripts/dds_security.sh) protects and encrypts the parameter
// request and reply topics and leaves telemetry and status readable (docs/hardware.md).
#pragma once

#include <cstdint>

#include <optional>
#include <string>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "config/supervisory_config.hpp"

namespace robodamp::dds {

enum class TopicKind { kTelemetry, kStatus, kRequest, kReply, kMachining, kAdvice, kSpectrum, kLobes };
inline constexpr int kTopicCount = 8;
// dds.transport: udp_loopback finds the participants on this host with ids 0 to this (Fast DDS numbers a
// host's participants from 0 in the order they start; an id above it is never discovered).
inline constexpr std::uint32_t kLoopbackParticipants = 32;

class Participant {
 public:
  // Throws std::runtime_error when the participant or a topic cannot be created.
  Participant(int domain_id, config::DdsTransport transport, const std::string& name,
              const std::optional<config::DdsSecurityConfig>& security = std::nullopt);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // Writers and readers with the topic's QoS (listener may be null). Deleted with the participant.
  eprosima::fastdds::dds::DataWriter* writer(TopicKind t,
                                             eprosima::fastdds::dds::DataWriterListener* listener = nullptr);
  eprosima::fastdds::dds::DataReader* reader(TopicKind t,
                                             eprosima::fastdds::dds::DataReaderListener* listener = nullptr);

  // ROS 2's sensor_msgs/msg/JointState on topic_name (dds.joint_states.topic): a reader that takes any
  // driver's writer (best effort, volatile, the last 8), and a writer as a ROS 2 driver has one (reliable,
  // volatile, the last 10: ROS 2's default QoS; tests and the HIL emulator).
  eprosima::fastdds::dds::DataReader* joint_state_reader(const std::string& topic_name,
                                                         eprosima::fastdds::dds::DataReaderListener* listener);
  eprosima::fastdds::dds::DataWriter* joint_state_writer(const std::string& topic_name);
  // ROS 2's trajectory_msgs/msg/JointTrajectory on topic_name (dds.path_ahead.topic): a reader that takes any
  // program's writer (best effort, volatile, the last 4), and a writer as a ROS 2 program has one (tests).
  eprosima::fastdds::dds::DataReader* trajectory_reader(const std::string& topic_name,
                                                        eprosima::fastdds::dds::DataReaderListener* listener);
  eprosima::fastdds::dds::DataWriter* trajectory_writer(const std::string& topic_name);

  [[nodiscard]] int domain_id() const { return domain_id_; }
  // The topic (its DDS name and type name: ROS 2's, see above).
  [[nodiscard]] eprosima::fastdds::dds::Topic* topic(TopicKind t);

 private:
  int domain_id_;
  config::DdsTransport transport_;
  eprosima::fastdds::dds::DomainParticipant* participant_{nullptr};
  eprosima::fastdds::dds::Publisher* publisher_{nullptr};
  eprosima::fastdds::dds::Subscriber* subscriber_{nullptr};
  eprosima::fastdds::dds::Topic* topics_[kTopicCount]{};
  eprosima::fastdds::dds::Topic* joint_state_topic(const std::string& topic_name);
  eprosima::fastdds::dds::Topic* joint_states_{nullptr};  // created on first use
  eprosima::fastdds::dds::Topic* trajectory_topic(const std::string& topic_name);
  eprosima::fastdds::dds::Topic* trajectories_{nullptr};  // created on first use
};

}  // namespace robodamp::dds
