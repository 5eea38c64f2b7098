// The non-real-time links of a robot cell: Modbus to the amplifier and the robot controller
// (drivers/modbus_client), the parameter sets the robot's mounting selects, Fast DDS telemetry and
// supervised parameters (dds/), and the hardware-in-the-loop emulator's pacing (robodamp plant).
// All optional: a configuration without them runs against the simulated plant in process.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace robodamp::config {

enum class ModbusTransport { kTcp, kRtu };

// One Modbus device: TCP (host, port) or RTU (serial line), and its unit (slave) id.
struct ModbusEndpoint {
  ModbusTransport transport{ModbusTransport::kTcp};
  std::string host{"127.0.0.1"};
  int port{502};
  std::string device{"/dev/ttyUSB0"};  // RTU
  int baud{115200};
  char parity{'N'};  // N, E, O
  int data_bits{8};
  int stop_bits{1};
  int unit_id{1};
};

// The amplifier's register map (zero-based protocol addresses).
struct AmplifierRegisters {
  int enable_coil{0};           // coil, written: 1 = enabled
  int ready_input{0};           // discrete input: enabled and able to drive
  int fault_input{1};           // discrete input: over-current, over-temperature, internal fault
  int temperature_register{0};  // input register, signed 16-bit count
  double temperature_c_per_count{0.1};
  double temperature_max_c{80.0};  // hotter than this is treated as an amplifier fault
};

// The robot controller's register that tells how the actuator is mounted at this pose.
struct RobotRegisters {
  int mounting_register{0};  // holding register
  int horizontal_value{0};
  int vertical_value{1};
  int settle_polls{3};  // the same value this many polls running before a set is selected
  // The spindle speed (docs/harmonic_notch.md): a holding register (-1 = none), scaled, with the same
  // settling; the robot link lost for modbus.link_timeout_s parks the harmonic notches.
  int spindle_rpm_register{-1};
  double rpm_per_count{1.0};
  // The joint angles (pose_schedule): consecutive holding registers from joints_register (-1 = none),
  // one per joint, signed 16-bit counts x deg_per_count; -32768 means "not available" (the robot's NaN).
  // The pose's region must read the same settle_polls polls running before a hand-over.
  int joints_register{-1};
  double deg_per_count{0.01};
  // Spindle-speed advice (runtime/speed_advisor.hpp) written for the robot program to read: four holding
  // registers from advice_register (-1 = none): the advice's sequence number (wraps at 65536), the advised
  // speed in rpm_per_count counts (0: none), the margin (advised limit / depth) x 100, and the status
  // (1: a speed advised, 2: no stable speed in the range, reduce the depth).
  int advice_register{-1};
  // The axial depth the robot program cuts (runtime/machining_monitor.hpp): a holding register (-1 =
  // none: the job's cut.axial_mm), unsigned counts x depth_mm_per_count; 65535 means "not available"
  // (the robot's NaN: the job's depth is used and the poll counted).
  int depth_register{-1};
  double depth_mm_per_count{0.001};
};

struct ModbusConfig {
  double poll_period_s{0.01};
  double response_timeout_s{0.1};
  double backoff_initial_s{0.05};
  double backoff_max_s{2.0};
  // No successful poll for this long while the amplifier is enabled (or asked to be): its status is
  // unknown, which the supervisor sees as an amplifier fault.
  double link_timeout_s{0.1};
  ModbusEndpoint amplifier_link;
  AmplifierRegisters amplifier;
  std::optional<ModbusEndpoint> robot_link;  // absent: no pose input
  RobotRegisters robot;
};

// Another controller parameter set: a configuration file (same loop rate) for another mounting.
struct ParameterSetRef {
  std::string mounting;  // horizontal | vertical
  std::string path;      // as written; resolved relative to the configuration file
  std::string resolved_path;
};

enum class DdsTransport { kUdpLoopback, kSharedMemory, kDefault };

// DDS Security (OMG DDS Security 1.1, Fast DDS's builtin plugins: PKI-DH authentication,
// Access-Permissions access control, AES-GCM-GMAC encryption). Paths are resolved against the
// configuration file's folder. docs/hardware.md says how to make them (scripts/dds_security.sh).
struct DdsSecurityConfig {
  std::string identity_ca;           // PEM: the CA that signs every participant's identity
  std::string identity_certificate;  // PEM: this participant's certificate
  std::string private_key;           // PEM: its key
  std::string permissions_ca;        // PEM: the CA that signs governance and permissions
  std::string governance;            // S/MIME-signed XML: which topics are protected, and how
  std::string permissions;           // S/MIME-signed XML: what this participant may publish and subscribe
};

// The robot's joint angles over DDS as a ROS 2 robot driver publishes them (sensor_msgs/msg/JointState,
// positions in radians; docs/pose_dynamics.md, "The pose over DDS"): the pose schedule's joints by name.
struct JointStatesConfig {
  std::string topic{"rt/joint_states"};  // DDS name: ROS 2's /joint_states
  std::vector<std::string> names;        // pose_schedule's joints, in its order, as the driver names them
  double timeout_s{0.5};                 // no message for this long: the pose is unknown
  int settle_samples{3};                 // a region counts once this many messages in a row fall in it
};

// The robot program's next poses over DDS (docs/pose_dynamics.md, "Advice along the path ahead"): ROS 2's
// trajectory_msgs/msg/JointTrajectory as a program sends it to its joint trajectory controller (positions in
// radians, each point's time_from_start); the speed advisor checks its candidates at those poses too.
struct PathAheadConfig {
  std::string topic{"rt/joint_trajectory"};  // DDS name: ROS 2's /joint_trajectory
  std::vector<std::string> names;  // pose_schedule's joints as the program names them (empty: dds.joint_states.names)
  double hold_s{10.0};             // an untimed point (time_from_start 0) stays ahead this long after the message
};

struct DdsConfig {
  int domain_id{0};
  DdsTransport transport{DdsTransport::kDefault};
  double telemetry_rate_hz{50.0};  // decimated loop frames
  double status_rate_hz{5.0};
  bool parameter_writes{false};                   // parameter requests are refused unless this is on
  std::optional<DdsSecurityConfig> security;      // absent: no authentication (a closed cell network)
  std::optional<JointStatesConfig> joint_states;  // absent: the pose comes from Modbus, or not at all
  std::optional<PathAheadConfig> path_ahead;      // absent: the advice looks at the pose now only
};

// The cell's identity on the network (docs/dashboard.md): every DDS topic carries it, a dashboard tells
// the cells apart by it and a parameter request names the cell it is for. 1-31 characters of letters,
// digits, '-', '_' and '.'; empty in the configuration: the host's name.
struct CellConfig {
  std::string name;
};
// The name a cell uses: cfg's, else the host's name (cut to the allowed characters), else "cell".
[[nodiscard]] std::string cell_name(const CellConfig& cfg);
// Why a name is not a name of 1 to max_chars letters, digits, '-', '_' and '.' (empty: it is); what: "cell
// name", "user name".
[[nodiscard]] std::string name_problem(const std::string& name, const std::string& what, std::size_t max_chars);
// Why a name is not a valid cell name (empty: it is).
[[nodiscard]] std::string cell_name_problem(const std::string& name);

enum class HilPacing { kRealtime, kLockstep };

struct HilConfig {
  HilPacing pacing{HilPacing::kRealtime};
  double settle_s{3.0};           // after the amplifier is enabled, before the first impact
  double accept_timeout_s{30.0};  // waiting for the controller to connect
  double amplifier_ready_delay_s{0.005};
  double ambient_c{35.0};
  double heating_c_per_v2{0.5};  // amplifier temperature above ambient per mean-square volt
  // The robot the emulator moves (a robot model file; empty: pose_schedule.model): a HIL cell that stands for
  // a robot its configured model does not describe, as a real robot is not its model file.
  std::string robot_model;           // as written
  std::string robot_model_resolved;  // resolved against the configuration file
};

[[nodiscard]] const char* to_string(ModbusTransport t);
[[nodiscard]] const char* to_string(DdsTransport t);
[[nodiscard]] const char* to_string(HilPacing p);
// "tcp 127.0.0.1:1502 unit 1" or "rtu /dev/ttyUSB0 115200 8N1 unit 1".
[[nodiscard]] std::string describe(const ModbusEndpoint& e);

}  // namespace robodamp::config
