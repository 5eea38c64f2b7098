// What `robodamp monitor` and `robodamp request` share: the DDS domain and transport, from the options
// or from a configuration's dds section (dds/client_options.hpp).
#pragma once

#include "apps/cli.hpp"
#include "dds/client_options.hpp"

namespace robodamp::apps {

using DdsClientArgs = dds::ClientRequest;
using DdsClientOptions = dds::ClientOptions;

void add_dds_options(Registry& r, CLI::App* sub, DdsClientArgs& a);

}  // namespace robodamp::apps
