#include "dds/participant.hpp"

#include <memory>
#include <stdexcept>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include "dds/messages.hpp"

namespace robodamp::dds {

using namespace eprosima::fastdds::dds;

namespace {
// ROS 2's names for the topics /robodamp/telemetry ... (ROS 2 prefixes its topics with rt/ in DDS).
constexpr const char* kTopicNames[kTopicCount] = {
    "rt/robodamp/telemetry", "rt/robodamp/status", "rt/robodamp/parameter_request", "rt/robodamp/parameter_reply",
    "rt/robodamp/machining", "rt/robodamp/advice", "rt/robodamp/spectrum",          "rt/robodamp/lobes"};
}  // namespace

Participant::Participant(int domain_id, config::DdsTransport transport, const std::string& name,
                         const std::optional<config::DdsSecurityConfig>& security)
    : domain_id_(domain_id), transport_(transport) {
  DomainParticipantQos pq = PARTICIPANT_QOS_DEFAULT;
  pq.name(name);
  if (security) {
    auto& props = pq.properties().properties();
    auto file = [](const std::string& path) { return "file://" + path; };
    props.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
    props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", file(security->identity_ca));
    props.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", file(security->identity_certificate));
    props.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", file(security->private_key));
    props.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
    props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", file(security->permissions_ca));
    props.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", file(security->governance));
    props.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", file(security->permissions));
    props.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  }
  if (transport == config::DdsTransport::kUdpLoopback) {
    pq.transport().use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    // The loopback has no multicast: discovery announces to the initial peer's ports of participant ids 0 to
    // this range. Fast DDS's default (4) never found a sixth participant on the host (a cell, two dashboards,
    // a monitor, a robot driver; DashboardFleet.ARestartedCellsLastRunIsDropped, the third fleet of its process).
    udp->maxInitialPeersRange = kLoopbackParticipants;
    pq.transport().user_transports.push_back(udp);
    eprosima::fastrtps::rtps::Locator_t peer;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, "127.0.0.1");
    pq.wire_protocol().builtin.initialPeersList.push_back(peer);
  } else if (transport == config::DdsTransport::kSharedMemory) {
    pq.transport().use_builtin_transports = false;
    pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
  }
  participant_ = DomainParticipantFactory::get_instance()->create_participant(domain_id, pq);
  if (participant_ == nullptr)
    throw std::runtime_error("DDS: cannot create a participant on domain " + std::to_string(domain_id) + " (" +
                             config::to_string(transport) + ")" +
                             (security ? ": check dds.security (certificates, key, signed governance and permissions, "
                                         "the subject names in the permissions)"
                                       : ""));
  TypeSupport types[kTopicCount] = {TypeSupport(new robodamp::msg::TelemetryPubSubType()),
                                    TypeSupport(new robodamp::msg::StatusPubSubType()),
                                    TypeSupport(new robodamp::msg::ParameterRequestPubSubType()),
                                    TypeSupport(new robodamp::msg::ParameterReplyPubSubType()),
                                    TypeSupport(new robodamp::msg::MachiningPubSubType()),
                                    TypeSupport(new robodamp::msg::AdvicePubSubType()),
                                    TypeSupport(new robodamp::msg::SpectrumPubSubType()),
                                    TypeSupport(new robodamp::msg::LobesPubSubType())};
  for (int i = 0; i < kTopicCount; ++i) {
    types[i].register_type(participant_);
    topics_[i] = participant_->create_topic(kTopicNames[i], types[i].get_type_name(), TOPIC_QOS_DEFAULT);
    if (topics_[i] == nullptr) throw std::runtime_error(std::string("DDS: cannot create topic ") + kTopicNames[i]);
  }
  publisher_ = participant_->create_publisher(PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr)
    throw std::runtime_error("DDS: cannot create publisher / subscriber");
}

Participant::~Participant() {
  if (participant_ != nullptr) {
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
}

Topic* Participant::topic(TopicKind t) { return topics_[static_cast<int>(t)]; }

namespace {
// A reader keeps more than a writer: the types have no key, so the samples of every cell on the domain
// share one instance, and a reader's keep-last-1 would let one cell's sample replace another's.
template <typename Qos>
void apply(Qos& q, TopicKind t, config::DdsTransport transport, bool reader) {
  if (t == TopicKind::kTelemetry) {
    q.reliability().kind = BEST_EFFORT_RELIABILITY_QOS;
    q.durability().kind = VOLATILE_DURABILITY_QOS;
    q.history().kind = KEEP_LAST_HISTORY_QOS;
    q.history().depth = reader ? 1024 : 64;
  } else {
    q.reliability().kind = RELIABLE_RELIABILITY_QOS;
    const bool latest = t == TopicKind::kStatus || t == TopicKind::kMachining || t == TopicKind::kAdvice ||
                        t == TopicKind::kSpectrum || t == TopicKind::kLobes;  // a late joiner gets the last
    q.durability().kind = latest ? TRANSIENT_LOCAL_DURABILITY_QOS : VOLATILE_DURABILITY_QOS;
    q.history().kind = KEEP_LAST_HISTORY_QOS;
    q.history().depth = reader ? 256 : latest ? 1 : 32;
  }
  if (transport == config::DdsTransport::kUdpLoopback) q.data_sharing().off();
}
}  // namespace

DataWriter* Participant::writer(TopicKind t, DataWriterListener* listener) {
  DataWriterQos q = DATAWRITER_QOS_DEFAULT;
  apply(q, t, transport_, false);
  DataWriter* w = publisher_->create_datawriter(topic(t), q, listener);
  if (w == nullptr)
    throw std::runtime_error(std::string("DDS: cannot create a writer on ") + kTopicNames[static_cast<int>(t)]);
  return w;
}

DataReader* Participant::reader(TopicKind t, DataReaderListener* listener) {
  DataReaderQos q = DATAREADER_QOS_DEFAULT;
  apply(q, t, transport_, true);
  DataReader* r = subscriber_->create_datareader(topic(t), q, listener);
  if (r == nullptr)
    throw std::runtime_error(std::string("DDS: cannot create a reader on ") + kTopicNames[static_cast<int>(t)]);
  return r;
}

}  // namespace robodamp::dds

namespace robodamp::dds {

namespace {

// A ROS 2 message's topic under the name the configuration gives (one per participant and message), created on
// first use.
template <typename PubSubType>
Topic* ros_topic(DomainParticipant* participant, Topic*& slot, const std::string& topic_name, const char* what) {
  if (slot != nullptr) {
    if (slot->get_name() != topic_name)
      throw std::runtime_error(std::string("DDS: ") + what + " on " + topic_name + " and " + slot->get_name() +
                               ": one topic");
    return slot;
  }
  TypeSupport type(new PubSubType());
  type.register_type(participant);
  slot = participant->create_topic(topic_name, type.get_type_name(), TOPIC_QOS_DEFAULT);
  if (slot == nullptr) throw std::runtime_error("DDS: cannot create topic " + topic_name);
  return slot;
}

// A reader that takes any ROS 2 writer (best effort matches a reliable writer and a best-effort one; volatile;
// the last `depth`), and a writer as a ROS 2 node has one (reliable, volatile, the last 10: ROS 2's default QoS).
DataReader* ros_reader(Subscriber* subscriber, Topic* topic, DataReaderListener* listener,
                       config::DdsTransport transport, int depth) {
  DataReaderQos q = DATAREADER_QOS_DEFAULT;
  q.reliability().kind = BEST_EFFORT_RELIABILITY_QOS;
  q.durability().kind = VOLATILE_DURABILITY_QOS;
  q.history().kind = KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  if (transport == config::DdsTransport::kUdpLoopback) q.data_sharing().off();
  DataReader* r = subscriber->create_datareader(topic, q, listener);
  if (r == nullptr) throw std::runtime_error("DDS: cannot create a reader on " + topic->get_name());
  return r;
}

DataWriter* ros_writer(Publisher* publisher, Topic* topic, config::DdsTransport transport) {
  DataWriterQos q = DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  q.durability().kind = VOLATILE_DURABILITY_QOS;
  q.history().kind = KEEP_LAST_HISTORY_QOS;
  q.history().depth = 10;
  if (transport == config::DdsTransport::kUdpLoopback) q.data_sharing().off();
  DataWriter* w = publisher->create_datawriter(topic, q);
  if (w == nullptr) throw std::runtime_error("DDS: cannot create a writer on " + topic->get_name());
  return w;
}

}  // namespace

Topic* Participant::joint_state_topic(const std::string& topic_name) {
  return ros_topic<msg::JointStatePubSubType>(participant_, joint_states_, topic_name, "joint states");
}

DataReader* Participant::joint_state_reader(const std::string& topic_name, DataReaderListener* listener) {
  return ros_reader(subscriber_, joint_state_topic(topic_name), listener, transport_, 8);
}

DataWriter* Participant::joint_state_writer(const std::string& topic_name) {
  return ros_writer(publisher_, joint_state_topic(topic_name), transport_);
}

Topic* Participant::trajectory_topic(const std::string& topic_name) {
  return ros_topic<msg::JointTrajectoryPubSubType>(participant_, trajectories_, topic_name, "trajectories");
}

DataReader* Participant::trajectory_reader(const std::string& topic_name, DataReaderListener* listener) {
  return ros_reader(subscriber_, trajectory_topic(topic_name), listener, transport_, 4);
}

DataWriter* Participant::trajectory_writer(const std::string& topic_name) {
  return ros_writer(publisher_, trajectory_topic(topic_name), transport_);
}

}  // namespace robodamp::dds
