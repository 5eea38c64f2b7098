#include "config/supervisory_config.hpp"

#include <algorithm>
#include <unistd.h>

#include <cctype>
#include <filesystem>

#include "config/config.hpp"
#include "config/file_paths.hpp"
#include "config/robot_model_config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config {

using detail::MapReader;
using detail::present;
using detail::Range;
using detail::read_bool;
using detail::read_int;

const char* to_string(ModbusTransport t) { return t == ModbusTransport::kTcp ? "tcp" : "rtu"; }
const char* to_string(DdsTransport t) {
  switch (t) {
    case DdsTransport::kUdpLoopback:
      return "udp_loopback";
    case DdsTransport::kSharedMemory:
      return "shared_memory";
    case DdsTransport::kDefault:
      break;
  }
  return "default";
}
const char* to_string(HilPacing p) { return p == HilPacing::kRealtime ? "realtime" : "lockstep"; }

std::string describe(const ModbusEndpoint& e) {
  if (e.transport == ModbusTransport::kTcp)
    return "tcp " + e.host + ":" + std::to_string(e.port) + " unit " + std::to_string(e.unit_id);
  return "rtu " + e.device + " " + std::to_string(e.baud) + " " + std::to_string(e.data_bits) + e.parity +
         std::to_string(e.stop_bits) + " unit " + std::to_string(e.unit_id);
}

std::optional<std::string> gain_request_problem(double gain_ns_per_m, double max_ns_per_m, const std::string& why) {
  return detail::range_problem("controller.gain_ns_per_m", gain_ns_per_m,
                               {"N s/m", 0.0, max_ns_per_m, false, false, why});
}

namespace detail {
namespace {

const Range kAddress{"(register address, zero-based)", 0, 65535};

ModbusEndpoint read_endpoint(MapReader& r) {
  ModbusEndpoint e;
  const auto t = r.choice("transport", {"tcp", "rtu"}, "tcp");
  e.transport = t && *t == "rtu" ? ModbusTransport::kRtu : ModbusTransport::kTcp;
  if (e.transport == ModbusTransport::kTcp) {
    e.host = r.text("host", e.host).value_or(e.host);
    if (auto v = read_int(r, "port", {"(TCP port)", 1, 65535})) e.port = *v;
  } else {
    e.device = r.text("device", std::nullopt).value_or(e.device);
    if (auto v = read_int(r, "baud", {"bit/s", 1200, 4'000'000}, e.baud)) e.baud = *v;
    if (auto v = r.choice("parity", {"none", "even", "odd"}, "none"))
      e.parity = *v == "none" ? 'N' : *v == "even" ? 'E' : 'O';
    if (auto v = read_int(r, "data_bits", {"bits", 7, 8}, e.data_bits)) e.data_bits = *v;
    if (auto v = read_int(r, "stop_bits", {"bits", 1, 2}, e.stop_bits)) e.stop_bits = *v;
  }
  if (auto v = read_int(r, "unit_id", {"(Modbus unit id)", e.transport == ModbusTransport::kTcp ? 0.0 : 1.0, 247},
                        e.unit_id))
    e.unit_id = *v;
  return e;
}

// long: every key of the modbus section with its unit and range, in the file's order
std::optional<ModbusConfig> read_modbus(MapReader& top) {
  const YAML::Node node = top.child("modbus", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(top.diagnostics(), node, "modbus", top.mark());
  ModbusConfig c;
  if (auto v = r.number("poll_period_s", {"s", 0.001, 10.0}, c.poll_period_s)) c.poll_period_s = *v;
  if (auto v = r.number("response_timeout_s", {"s", 0.001, 10.0}, c.response_timeout_s)) c.response_timeout_s = *v;
  if (auto v = r.number("backoff_initial_s", {"s", 0.001, 10.0}, c.backoff_initial_s)) c.backoff_initial_s = *v;
  if (auto v = r.number("backoff_max_s", {"s", 0.001, 600.0}, c.backoff_max_s)) c.backoff_max_s = *v;
  if (c.backoff_max_s < c.backoff_initial_s)
    r.diagnostics().add(r.mark(), "modbus.backoff_max_s",
                        "= " + format_number(c.backoff_max_s) +
                            " s is below modbus.backoff_initial_s = " + format_number(c.backoff_initial_s) + " s");
  if (auto v = r.number("link_timeout_s", {"s", 0.001, 60.0}, c.link_timeout_s)) c.link_timeout_s = *v;
  if (c.link_timeout_s < c.poll_period_s)
    r.diagnostics().add(r.mark(), "modbus.link_timeout_s",
                        "= " + format_number(c.link_timeout_s) + " s is shorter than modbus.poll_period_s = " +
                            format_number(c.poll_period_s) + " s: every poll would count as a lost link");

  MapReader a(r.diagnostics(), r.child("amplifier", true, "the amplifier's endpoint and registers"), "modbus.amplifier",
              r.mark());
  c.amplifier_link = read_endpoint(a);
  auto& ar = c.amplifier;
  if (auto v = read_int(a, "enable_coil", kAddress, ar.enable_coil)) ar.enable_coil = *v;
  if (auto v = read_int(a, "ready_input", kAddress, ar.ready_input)) ar.ready_input = *v;
  if (auto v = read_int(a, "fault_input", kAddress, ar.fault_input)) ar.fault_input = *v;
  if (ar.ready_input == ar.fault_input)
    a.diagnostics().add(a.mark(), "modbus.amplifier.fault_input",
                        "= " + std::to_string(ar.fault_input) + " is the ready input's address too: they must differ");
  if (auto v = read_int(a, "temperature_register", kAddress, ar.temperature_register)) ar.temperature_register = *v;
  if (auto v = a.number("temperature_c_per_count", {"degC per count", 0.0, 100.0, true}, ar.temperature_c_per_count))
    ar.temperature_c_per_count = *v;
  if (auto v = a.number("temperature_max_c", {"degC", 0.0, 200.0}, ar.temperature_max_c)) ar.temperature_max_c = *v;
  a.finish();

  const YAML::Node rn = r.child("robot", false, "");
  if (present(rn)) {
    MapReader b(r.diagnostics(), rn, "modbus.robot", r.mark());
    c.robot_link = read_endpoint(b);
    auto& rr = c.robot;
    if (auto v = read_int(b, "mounting_register", kAddress, rr.mounting_register)) rr.mounting_register = *v;
    if (auto v = read_int(b, "horizontal_value", {"(register value)", 0, 65535}, rr.horizontal_value))
      rr.horizontal_value = *v;
    if (auto v = read_int(b, "vertical_value", {"(register value)", 0, 65535}, rr.vertical_value))
      rr.vertical_value = *v;
    if (rr.horizontal_value == rr.vertical_value)
      b.diagnostics().add(b.mark(), "modbus.robot.vertical_value",
                          "= " + std::to_string(rr.vertical_value) + " is the horizontal value too: they must differ");
    if (auto v = read_int(b, "settle_polls", {"(polls)", 1, 1000}, rr.settle_polls)) rr.settle_polls = *v;
    if (auto v = read_int(b, "spindle_rpm_register", {"(register address, zero-based; -1 = none)", -1, 65535},
                          rr.spindle_rpm_register))
      rr.spindle_rpm_register = *v;
    if (rr.spindle_rpm_register >= 0 && rr.spindle_rpm_register == rr.mounting_register)
      b.diagnostics().add(
          b.mark(), "modbus.robot.spindle_rpm_register",
          "= " + std::to_string(rr.spindle_rpm_register) + " is the mounting register too: they must differ");
    if (auto v = b.number("rpm_per_count", {"rpm per count", 0.0, 1000.0, true}, rr.rpm_per_count))
      rr.rpm_per_count = *v;
    if (auto v = read_int(b, "joints_register", {"(register address, zero-based; -1 = none)", -1, 65535},
                          rr.joints_register))
      rr.joints_register = *v;
    if (auto v = b.number("deg_per_count", {"deg per count", 0.0, 1.0, true}, rr.deg_per_count)) rr.deg_per_count = *v;
    if (auto v = read_int(b, "advice_register", {"(register address, zero-based, 4 registers; -1 = none)", -1, 65532},
                          rr.advice_register))
      rr.advice_register = *v;
    if (auto v =
            read_int(b, "depth_register", {"(register address, zero-based; -1 = none)", -1, 65535}, rr.depth_register))
      rr.depth_register = *v;
    if (auto v = b.number("depth_mm_per_count", {"mm per count", 0.0, 1.0, true}, rr.depth_mm_per_count))
      rr.depth_mm_per_count = *v;
    for (const auto& [key, reg] : {std::pair{"mounting_register", rr.mounting_register},
                                   std::pair{"spindle_rpm_register", rr.spindle_rpm_register}})
      if (rr.depth_register >= 0 && reg == rr.depth_register)
        b.diagnostics().add(
            b.mark(), "modbus.robot.depth_register",
            "= " + std::to_string(rr.depth_register) + " is modbus.robot." + key + " too: they must differ");
    for (const auto& [key, reg] :
         {std::pair{"mounting_register", rr.mounting_register},
          std::pair{"spindle_rpm_register", rr.spindle_rpm_register}, std::pair{"depth_register", rr.depth_register}})
      if (rr.advice_register >= 0 && reg >= rr.advice_register && reg < rr.advice_register + 4)
        b.diagnostics().add(b.mark(), "modbus.robot.advice_register",
                            "= " + std::to_string(rr.advice_register) + " covers registers " +
                                std::to_string(rr.advice_register) + "-" + std::to_string(rr.advice_register + 3) +
                                ", which holds modbus.robot." + key + " = " + std::to_string(reg) +
                                ": they must differ");
    b.finish();
  }
  r.finish();
  return c;
}

std::vector<ParameterSetRef> read_parameter_sets(MapReader& top, const std::string& source) {
  const YAML::Node node = top.child("parameter_sets", false, "");
  std::vector<ParameterSetRef> sets;
  if (!present(node)) return sets;
  MapReader r(top.diagnostics(), node, "parameter_sets", top.mark());
  const std::filesystem::path dir = std::filesystem::path(source).parent_path();
  for (const char* m : {"horizontal", "vertical"}) {
    const auto p = r.text(m, "");
    if (!p || p->empty()) continue;
    const FoundFile f = find_named_file(dir.string(), *p);
    ParameterSetRef s{m, *p, f.path};
    if (!f.found)
      r.diagnostics().add(r.mark(), "parameter_sets." + s.mounting,
                          "= '" + s.path + "': no such file (looked for " + f.looked_text() + ")");
    else
      sets.push_back(std::move(s));
  }
  r.finish();
  return sets;
}

std::optional<DdsSecurityConfig> read_dds_security(MapReader& dds, const std::string& source) {
  const YAML::Node node = dds.child("security", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(dds.diagnostics(), node, "dds.security", dds.mark());
  const std::filesystem::path dir = std::filesystem::path(source).parent_path();
  DdsSecurityConfig c;
  const std::pair<const char*, std::string*> files[] = {
      {"identity_ca", &c.identity_ca}, {"identity_certificate", &c.identity_certificate},
      {"private_key", &c.private_key}, {"permissions_ca", &c.permissions_ca},
      {"governance", &c.governance},   {"permissions", &c.permissions}};
  for (const auto& [key, out] : files) {
    const auto p = r.text(key, std::nullopt);
    if (!p) continue;
    const std::filesystem::path resolved =
        std::filesystem::path(*p).is_absolute() ? std::filesystem::path(*p) : dir / *p;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(resolved, ec))
      r.diagnostics().add(r.mark(), r.path_of(key),
                          "= '" + *p + "': no such file (looked for " + resolved.string() + ")");
    *out = resolved.string();
  }
  r.finish();
  return c;
}

// A list of joint names at `key` of r (each once, text), into out.
void read_joint_names(MapReader& r, const std::string& key, const char* what, std::vector<std::string>& out) {
  const YAML::Node names = r.child("names", false, what);
  if (present(names) && !names.IsSequence())
    r.diagnostics().add(to_mark(names.Mark()), key, "must be a list of joint names, e.g. [joint_1, joint_2]");
  else if (present(names))
    for (std::size_t i = 0; i < names.size(); ++i) {
      const std::string at = key + "[" + std::to_string(i) + "]";
      const std::string name = names[i].IsScalar() ? names[i].as<std::string>() : "";
      if (name.empty())
        r.diagnostics().add(to_mark(names[i].Mark()), at, "must be a joint's name (text)");
      else if (std::find(out.begin(), out.end(), name) != out.end())
        r.diagnostics().add(to_mark(names[i].Mark()), at, "= '" + name + "' is named twice: each joint once");
      if (!name.empty()) out.push_back(name);  // kept, so the count is the file's
    }
}

std::optional<PathAheadConfig> read_path_ahead(MapReader& dds) {
  const YAML::Node node = dds.child("path_ahead", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(dds.diagnostics(), node, "dds.path_ahead", dds.mark());
  PathAheadConfig c;
  if (auto v = r.text("topic", c.topic)) c.topic = *v;
  read_joint_names(r, "dds.path_ahead.names", "the pose schedule's joints by the names the robot program publishes",
                   c.names);
  if (auto v = r.number("hold_s", {"s", 0.1, 3600.0}, c.hold_s)) c.hold_s = *v;
  r.finish();
  return c;
}

std::optional<JointStatesConfig> read_joint_states(MapReader& dds) {
  const YAML::Node node = dds.child("joint_states", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(dds.diagnostics(), node, "dds.joint_states", dds.mark());
  JointStatesConfig c;
  if (auto v = r.text("topic", c.topic)) c.topic = *v;
  (void)r.child("names", true, "the pose schedule's joints by the names the robot's driver publishes");
  read_joint_names(r, "dds.joint_states.names", "", c.names);
  if (auto v = r.number("timeout_s", {"s", 0.01, 60.0}, c.timeout_s)) c.timeout_s = *v;
  if (auto v = read_int(r, "settle_samples", {"(messages)", 1, 1000}, c.settle_samples)) c.settle_samples = *v;
  r.finish();
  return c;
}

std::optional<DdsConfig> read_dds(MapReader& top) {
  const YAML::Node node = top.child("dds", false, "");
  if (!present(node)) return std::nullopt;
  MapReader r(top.diagnostics(), node, "dds", top.mark());
  DdsConfig c;
  if (auto v = read_int(r, "domain_id", {"(DDS domain)", 0, 232}, c.domain_id)) c.domain_id = *v;
  if (auto v = r.choice("transport", {"default", "udp_loopback", "shared_memory"}, "default"))
    c.transport = *v == "udp_loopback"    ? DdsTransport::kUdpLoopback
                  : *v == "shared_memory" ? DdsTransport::kSharedMemory
                                          : DdsTransport::kDefault;
  if (auto v = r.number("telemetry_rate_hz", {"Hz", 0.0, 1000.0, true}, c.telemetry_rate_hz)) c.telemetry_rate_hz = *v;
  if (auto v = r.number("status_rate_hz", {"Hz", 0.0, 100.0, true}, c.status_rate_hz)) c.status_rate_hz = *v;
  if (auto v = read_bool(r, "parameter_writes", c.parameter_writes)) c.parameter_writes = *v;
  c.security = read_dds_security(r, top.diagnostics().file());
  c.joint_states = read_joint_states(r);
  c.path_ahead = read_path_ahead(r);
  if (c.path_ahead && c.path_ahead->names.empty() && c.joint_states) c.path_ahead->names = c.joint_states->names;
  r.finish();
  return c;
}

CellConfig read_cell(MapReader& top) {
  MapReader r(top.diagnostics(), top.child("cell", false, ""), "cell", top.mark());
  CellConfig c;
  if (auto v = r.text("name", std::string{})) {
    if (const std::string problem = cell_name_problem(*v); !v->empty() && !problem.empty())
      r.diagnostics().add(r.mark(), "cell.name", "= \"" + v->substr(0, 64) + "\" " + problem);
    else
      c.name = *v;
  }
  r.finish();
  return c;
}

HilConfig read_hil(MapReader& top, const std::string& source) {
  MapReader r(top.diagnostics(), top.child("hil", false, ""), "hil", top.mark());
  HilConfig c;
  if (auto v = r.text("robot_model", std::string()); v && !v->empty())
    (void)read_robot_model_file(r, "hil.robot_model", source, *v, c.robot_model, c.robot_model_resolved);
  if (auto v = r.choice("pacing", {"realtime", "lockstep"}, "realtime"))
    c.pacing = *v == "lockstep" ? HilPacing::kLockstep : HilPacing::kRealtime;
  if (auto v = r.number("settle_s", {"s", 0.0, 600.0}, c.settle_s)) c.settle_s = *v;
  if (auto v = r.number("accept_timeout_s", {"s", 0.0, 3600.0, true}, c.accept_timeout_s)) c.accept_timeout_s = *v;
  if (auto v = r.number("amplifier_ready_delay_s", {"s", 0.0, 10.0}, c.amplifier_ready_delay_s))
    c.amplifier_ready_delay_s = *v;
  if (auto v = r.number("ambient_c", {"degC", -40.0, 100.0}, c.ambient_c)) c.ambient_c = *v;
  if (auto v = r.number("heating_c_per_v2", {"degC per V^2", 0.0, 100.0}, c.heating_c_per_v2)) c.heating_c_per_v2 = *v;
  r.finish();
  return c;
}

}  // namespace

std::optional<DdsConfig> read_dds_section(MapReader& top) { return read_dds(top); }

void read_supervisory(MapReader& top, Config& c) {
  c.modbus = read_modbus(top);
  c.parameter_sets = read_parameter_sets(top, c.source);
  c.dds = read_dds(top);
  c.cell = read_cell(top);
  c.hil = read_hil(top, c.source);
  if (!c.parameter_sets.empty() && !(c.modbus && c.modbus->robot_link))
    top.diagnostics().add(top.mark(), "parameter_sets",
                          "needs modbus.robot: the robot's mounting register is what selects a set");
}

}  // namespace detail

std::string name_problem(const std::string& name, const std::string& what, std::size_t max_chars) {
  if (name.empty() || name.size() > max_chars)
    return "is not a " + what + ": allowed 1 to " + std::to_string(max_chars) + " characters";
  for (const char ch : name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_' || ch == '.'))
      return "is not a " + what + ": allowed letters, digits, '-', '_' and '.'";
  return {};
}

std::string cell_name_problem(const std::string& name) { return name_problem(name, "cell name", 31); }

std::string cell_name(const CellConfig& cfg) {
  if (!cfg.name.empty()) return cfg.name;
  char host[256] = {};
  std::string name;
  if (gethostname(host, sizeof host - 1) == 0)
    for (const char* p = host; *p != '\0' && name.size() < 31; ++p)
      if (std::isalnum(static_cast<unsigned char>(*p)) || *p == '-' || *p == '_' || *p == '.') name += *p;
  return name.empty() ? "cell" : name;
}

}  // namespace robodamp::config
