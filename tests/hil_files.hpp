// config/hil_horizontal_c2.yaml for one cross-process test: its own CAN socket (in the test's
// directory) and a free Modbus TCP port, the vertical parameter set by absolute path, plus edits.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace robodamp::test {

// A TCP port on loopback that nothing listens on, drawn at random from below the kernel's ephemeral range
// (/proc/sys/net/ipv4/ip_local_port_range) and tried by a bind. Not a port the kernel hands out and takes back
// (bind to 0): the emulator listens on it up to minutes later, and such a port was once taken by then as the
// local end of another test's Modbus connection ("Address already in use"). Below the range, no connection's
// local end takes it; another test drawing the same one of ~20 000 ports at the same moment is what remains.
inline int free_tcp_port() {
  int ephemeral_low = 32768;
  std::ifstream("/proc/sys/net/ipv4/ip_local_port_range") >> ephemeral_low;
  const int first = 10000, last = std::max(first + 1000, ephemeral_low) - 1;
  std::mt19937 rng(std::random_device{}() ^ static_cast<unsigned>(getpid()));
  std::uniform_int_distribution<int> draw(first, last);
  for (int tries = 0; tries < 1000; ++tries) {
    const int port = draw(rng);
    const int s = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    const bool bound = s >= 0 && bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    if (s >= 0) close(s);
    if (bound) return port;
  }
  throw std::runtime_error("free_tcp_port: no free TCP port on loopback in " + std::to_string(first) + "-" +
                           std::to_string(last));
}

// Every occurrence; returns how many.
inline std::size_t replace_all_present(std::string& s, const std::string& from, const std::string& to) {
  std::size_t n = 0;
  for (std::size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size()), ++n)
    s.replace(p, from.size(), to);
  return n;
}

struct HilFiles {
  std::string dir, config, plant_json, run_json, plant_log, run_log;
};

// config/<base>.yaml with this test's own socket and Modbus port.
inline HilFiles hil_files(const std::string& name, const std::vector<std::pair<std::string, std::string>>& edits = {},
                          const std::string& base = "hil_horizontal_c2") {
  HilFiles f;
  f.dir = ::testing::TempDir() + "robodamp_hil_" + name + "_" + std::to_string(getpid());
  mkdir(f.dir.c_str(), 0755);
  std::string text = test::read_file(std::string(ROBODAMP_SOURCE_DIR) + "/config/" + base + ".yaml");
  // Each base file has some of these.
  replace_all_present(text, "unix:/tmp/robodamp-hil.sock", "unix:" + f.dir + "/can.sock");
  replace_all_present(text, "unix:/tmp/robodamp-hil-cut.sock", "unix:" + f.dir + "/can.sock");
  replace_all_present(text, "job: milling/", std::string("job: ") + ROBODAMP_SOURCE_DIR + "/config/milling/");
  replace_all_present(text, "model: robots/", std::string("model: ") + ROBODAMP_SOURCE_DIR + "/config/robots/");
  replace_all_present(text, "port: 1502", "port: " + std::to_string(free_tcp_port()));
  replace_all_present(text, "vertical: presets/vertical_c1.yaml",
                      std::string("vertical: ") + ROBODAMP_SOURCE_DIR + "/config/presets/vertical_c1.yaml");
  // The emulator's wait for the controller stretched by the build's pace (test::pace): an instrumented
  // `robodamp run` beside a loaded suite took more than the 30 s to connect.
  replace_all_present(text, "accept_timeout_s: 30", "accept_timeout_s: " + config::format_number(30.0 * test::pace()));
  for (const auto& [from, to] : edits) replace_or_throw(text, from, to);  // a test's own edit must match
  f.config = f.dir + "/hil.yaml";
  std::ofstream(f.config) << text;
  f.plant_json = f.dir + "/plant.json";
  f.run_json = f.dir + "/run.json";
  f.plant_log = f.dir + "/plant.log";
  f.run_log = f.dir + "/run.log";
  return f;
}

}  // namespace robodamp::test
