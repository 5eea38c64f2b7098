#include "apps/dds_client.hpp"

namespace robodamp::apps {

void add_dds_options(Registry& r, CLI::App* sub, DdsClientArgs& a) {
  r.whole_number(sub, "--domain", a.domain, {"(DDS domain id)", 0, 232},
                 "DDS domain (default: dds.domain_id of --config, else 0)");
  sub->add_option("--config", a.config_path, "Take the domain and transport from this configuration's dds section")
      ->check(CLI::ExistingFile);
  sub->add_option("--transport", a.transport, "default, udp_loopback or shared_memory")
      ->check(CLI::IsMember({"default", "udp_loopback", "shared_memory"}));
  sub->add_option("--cell", a.cell,
                  "The cell (its cell.name; default: the --config's cell.name, or with no --config, "
                  "for a request this host's name)")
      ->check([](const std::string& v) {
        const std::string p = config::cell_name_problem(v);
        return p.empty() ? std::string() : "--cell = \"" + v.substr(0, 64) + "\" " + p;
      });
}

}  // namespace robodamp::apps
