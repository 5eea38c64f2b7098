#include "config/dashboard_config.hpp"

#include <filesystem>

#include "config/config.hpp"
#include "config/yaml_reader.hpp"

namespace robodamp::config {

using detail::MapReader;

namespace {

std::string resolve(const std::string& path, const std::string& source) {
  if (path.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(source).parent_path() / path).string();
}

void read_dashboard(MapReader& top, DashboardConfig& c) {
  MapReader r(top.diagnostics(), top.child("dashboard", false, ""), "dashboard", top.mark());
  if (auto v = r.text("listen_address", c.listen_address)) c.listen_address = *v;
  if (auto v = detail::read_int(r, "port", {"(TCP port)", 0, 65535, false, false, "0 = any free port"}, c.port))
    c.port = *v;
  if (auto v = r.text("credentials", std::string{})) c.credentials = resolve(*v, c.source);
  if (auto v = r.text("action_log", std::string{})) c.action_log = resolve(*v, c.source);
  if (auto v = r.text("tls_certificate", std::string{})) c.tls_certificate = resolve(*v, c.source);
  if (auto v = r.text("tls_private_key", std::string{})) c.tls_private_key = resolve(*v, c.source);
  if (auto v = r.number("session_idle_s", {"s", 1.0, 7 * 86400.0}, c.session_idle_s)) c.session_idle_s = *v;
  if (auto v = r.number("stale_after_s", {"s", 0.1, 3600.0}, c.stale_after_s)) c.stale_after_s = *v;
  if (auto v = r.number("reply_timeout_s", {"s", 0.1, 60.0}, c.reply_timeout_s)) c.reply_timeout_s = *v;
  if (auto v = detail::read_int(r, "max_event_streams", {"(streams)", 1, 256}, c.max_event_streams))
    c.max_event_streams = *v;
  if (auto v = detail::read_int(r, "max_body_bytes", {"bytes", 256, 1 << 20}, static_cast<int>(c.max_body_bytes)))
    c.max_body_bytes = static_cast<std::size_t>(*v);
  r.finish();
  std::error_code ec;
  if (!c.credentials.empty() && !std::filesystem::is_regular_file(c.credentials, ec))
    top.diagnostics().add(r.mark(), "dashboard.credentials",
                          "= '" + c.credentials + "': no such file (robodamp dashboard-user makes one)");
  if (c.tls_certificate.empty() != c.tls_private_key.empty())
    top.diagnostics().add(r.mark(),
                          c.tls_certificate.empty() ? "dashboard.tls_certificate" : "dashboard.tls_private_key",
                          "not given: HTTPS needs both the certificate and its private key");
  for (const auto& [key, path] :
       {std::pair{"dashboard.tls_certificate", c.tls_certificate}, {"dashboard.tls_private_key", c.tls_private_key}})
    if (!path.empty() && !std::filesystem::is_regular_file(path, ec))
      top.diagnostics().add(r.mark(), key,
                            "= '" + path + "': no such file (robodamp dashboard-cert makes a self-signed pair)");
}

}  // namespace

DashboardConfig parse_dashboard_config(const std::string& yaml_text, const std::string& source_name) {
  detail::Diagnostics d(source_name);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError({Problem{source_name, detail::to_mark(e.mark), "(file)", std::string("is not YAML: ") + e.msg}});
  }
  if (!root.IsMap()) throw ConfigError({Problem{source_name, {}, "(file)", "must be a map with a dashboard section"}});
  DashboardConfig c;
  c.source = source_name;
  MapReader top(d, root, "", root.Mark());
  read_dashboard(top, c);
  if (auto dds = detail::read_dds_section(top)) c.dds = *dds;
  top.finish();
  if (!d.problems().empty()) throw ConfigError(located(d.problems(), yaml_text));
  if (c.action_log.empty() && !c.credentials.empty()) c.action_log = c.credentials + ".actions.log";
  return c;
}

DashboardConfig load_dashboard_config(const std::string& path) {
  return parse_dashboard_config(detail::read_config_text(path), path);
}

}  // namespace robodamp::config
