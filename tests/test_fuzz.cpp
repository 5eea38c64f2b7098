// Hostile input, seeded and bounded: random command lines over every subcommand (each one in a forked
// child, so a crash or a hang is caught and reported with the arguments), mutated configuration files
// and milling jobs, and corrupted recordings. Each fuzzer prints its counts.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "apps/cli.hpp"
#include "config/milling_config.hpp"
#include "cell_util.hpp"
#include "analysis/chain_design.hpp"
#include "milling/structure.hpp"
#include "rt/recording.hpp"
#include "sim_plant/plant_model.hpp"
#include "test_util.hpp"

namespace robodamp {
namespace {

namespace fs = std::filesystem;
using Rng = std::mt19937_64;

std::size_t below(Rng& rng, std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); }
template <typename T>
const T& one_of(Rng& rng, const std::vector<T>& v) {
  return v[below(rng, v.size())];
}

fs::path scratch(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / name;  // the process's own (tests/test_main.cpp)
  fs::create_directories(p.parent_path());
  return p;
}

// --- command lines --------------------------------------------------------------------------------------

struct ChildResult {
  int status{-1};  // exit status, 128 + signal, or -1 for a hang (killed)
  std::string err;
};

// dispatch() in a forked child, stdout discarded, stderr captured; killed after timeout_s.
ChildResult run_in_child(const std::vector<std::string>& args, double timeout_s) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(fds[1], 2);
    std::vector<const char*> argv{"robodamp"};
    for (const auto& a : args) argv.push_back(a.c_str());
    const int rc = apps::dispatch(static_cast<int>(argv.size()), argv.data());
    std::fflush(nullptr);
    _exit(rc);
  }
  close(fds[1]);
  ChildResult r;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  char buf[4096];
  bool hung = false;
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      hung = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left)) <= 0) continue;
    const ssize_t n = read(fds[0], buf, sizeof buf);
    if (n <= 0) break;  // EOF: the child has exited (or closed stderr)
    r.err.append(buf, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  if (hung) kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  r.status = hung ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

struct Sub {
  std::string name;
  std::vector<std::string> numbers;                                       // numeric options
  std::vector<std::string> flags;                                         // options without a value
  std::vector<std::pair<std::string, std::vector<std::string>>> choices;  // options with valid values
  std::vector<std::string> files;                                         // options taking an existing file
  bool positional_file{false};
};

std::vector<Sub> subcommands() {
  const std::string c2 = test::preset("horizontal_c2");
  return {
      {"filters", {"--freq"}, {"--json"}, {}, {"--config"}, false},
      {"check-config", {}, {}, {}, {}, true},
      {"analyze", {"--spindle-rpm"}, {"--json", "--spindle-sweep", "--no-pose-schedule"}, {}, {"--config"}, false},
      {"bench", {}, {}, {}, {"--config"}, false},
      {"run",
       {"--duration", "--impact-every", "--spindle-rpm", "--pose"},
       {"--no-pose-schedule"},
       {{"--clock", {"wall", "virtual"}}},
       {"--config", "--job"},
       false},
      {"plant",
       {"--duration", "--impact-location", "--spindle-register-period", "--pose-register-period", "--pose-update"},
       {"--no-impacts"},
       {{"--pacing", {"realtime", "lockstep"}}},
       {"--config"},
       false},
      {"monitor",
       {"--domain", "--duration"},
       {},
       {{"--transport", {"default", "udp_loopback", "shared_memory"}}},
       {"--config"},
       false},
      {"request",
       {"--domain", "--gain", "--select", "--enable", "--timeout", "--spindle-rpm"},
       {},
       {{"--transport", {"default", "udp_loopback"}}},
       {"--config"},
       false},
      {"dashboard",
       {"--port", "--domain", "--duration"},
       {},
       {{"--transport", {"default", "udp_loopback"}}},
       {"--config"},
       false},
      {"replay", {}, {}, {}, {}, true},
      {"csv", {}, {}, {}, {}, true},
      {"lobes", {"--rpm", "--pose"}, {"--json", "--damped"}, {}, {"--job", "--controller"}, false},
      {"sle", {"--pose"}, {"--json", "--damped"}, {}, {"--job", "--controller"}, false},
      {"cut",
       {"--rpm", "--axial-mm", "--radial-mm", "--revs", "--pose"},
       {"--critical", "--damped"},
       {},
       {"--job"},
       false},
      {"identify",
       {"--teeth", "--diameter-mm", "--axial-mm", "--radial-mm", "--band-hz", "--max-order", "--segment-s", "--overlap",
        "--helix-deg", "--order", "--record", "--feeds-mm", "--rpm"},
       {"--ball-end"},
       {{"--mode", {"down", "up"}},
        {"--kind", {"receptance", "mobility", "accelerance"}},
        {"--response", {"acceleration", "velocity", "1:+Y"}},
        {"--reference", {"1:+Y", "2:-Z"}},
        {"--axes", {"fx,fy,fz", "-fy,fx,fz"}},
        {"--force-on", {"workpiece", "tool"}}},
       {"--csv", "--frf", "--series", "--recording", "--structure", "--records", "--tests", "--uff", "--config"},
       false},
      {"measure", {}, {}, {{"--clock", {"wall", "virtual"}}}, {"--config"}, false},
      {"chatter",
       {"--teeth", "--rpm", "--rpm-range", "--rate-hz", "--channel", "--full-scale-mps2", "--record", "--window-s",
        "--max-hz", "--floor"},
       {"--json"},
       {{"--response", {"1:+Y"}}, {"--column", {"2", "accel"}}},
       {"--signal"},
       false},
      {"tune",
       {"--gain-margin-db", "--phase-margin-deg", "--delay-margin-ms", "--depth-at-speed-mm", "--evaluations",
        "--polish", "--seed", "--restarts", "--shift-pct", "--impact-n", "--impact-ms"},
       {},
       {},
       {"--config", "--job", "--also"},
       false},
      {"pose",
       {"--joints", "--modes", "--band-hz", "--steps", "--fit-band-hz", "--restarts", "--particles", "--iterations",
        "--seed", "--csv-step-hz"},
       {"--json"},
       {{"--direction", {"xx", "yy", "xy"}}},
       {"--model", "--job"},
       false},
  };
}

// Invalid for every numeric option (all allow only finite values in [0, 1e6] at most).
const std::vector<std::string> kBadNumbers{"nan",   "-nan",   "NaN",      "inf",  "-inf",  "Infinity",
                                           "1e999", "-1e999", "1e9",      "-1e9", "1e300", "abc",
                                           "",      "12abc",  "1.5.5",    "+-1",  "0x",    "--",
                                           " ",     "1,5",    "\xff\xfe", "1e",   "-",     "99999999999999999999999"};
const std::vector<std::string> kFine{"0.5", "1", "2", "0", "10", "100"};

// One argument vector with at least one element the parser must refuse, in a random place.
std::vector<std::string> hostile_args(Rng& rng, const std::vector<Sub>& subs, std::string& why) {
  const Sub& s = one_of(rng, subs);
  std::vector<std::vector<std::string>> parts;  // option groups, shuffled later
  const std::string c2 = test::preset("horizontal_c2");
  for (std::size_t i = below(rng, 4); i > 0; --i) {  // benign options first
    switch (below(rng, 3)) {
      case 0:
        if (!s.flags.empty()) {
          // --json takes an optional FILE (docs/cli.md): given as "--json -" so that a hostile token
          // shuffled after it stays a token the parser must refuse, not the JSON's file name.
          const std::string f = one_of(rng, s.flags);
          parts.push_back(f == "--json" ? std::vector<std::string>{f, "-"} : std::vector<std::string>{f});
        }
        break;
      case 1:
        if (!s.choices.empty()) {
          const auto& c = one_of(rng, s.choices);
          parts.push_back({c.first, one_of(rng, c.second)});
        }
        break;
      default:
        if (!s.files.empty()) parts.push_back({one_of(rng, s.files), c2});
    }
  }
  std::vector<std::string> hostile;
  switch (below(rng, 8)) {
    case 0:
    case 1:
    case 2:
      if (!s.numbers.empty()) {
        hostile = {one_of(rng, s.numbers), one_of(rng, kBadNumbers)};
        why = "bad number";
        break;
      }
      [[fallthrough]];
    case 3:
      hostile = {
          one_of(rng, std::vector<std::string>{"--bogus", "-x", "--rpm=", "--config=", "---", "--duration=nan", "-q"})};
      if (hostile[0] == "--duration=nan" && s.name != "run" && s.name != "plant" && s.name != "monitor")
        hostile = {"--Config"};
      if (s.name == "lobes" && hostile[0] == "--rpm=") hostile = {"--rpm", "nan"};
      if (hostile[0] == "--config=" && !s.files.empty()) hostile = {"--config", "/nonexistent/robodamp.yaml"};
      why = "unknown or malformed option";
      break;
    case 4:
      hostile = {s.files.empty() ? "--config" : one_of(rng, s.files), "/nonexistent/dir/robodamp.yaml"};
      if (s.positional_file) hostile = {"/nonexistent/dir/robodamp.rec"};
      why = "missing file";
      break;
    case 5:
      if (!s.choices.empty()) {
        hostile = {one_of(rng, s.choices).first, one_of(rng, std::vector<std::string>{"", "WALL", "tcp", "1", "nan"})};
        why = "bad choice";
        break;
      }
      [[fallthrough]];
    case 6:
      hostile = {!s.numbers.empty() ? one_of(rng, s.numbers) : "--config"};  // value missing at the end
      why = "value missing";
      break;
    default: {
      std::string junk;
      for (std::size_t i = 1 + below(rng, 12); i > 0; --i) junk += static_cast<char>(1 + below(rng, 255));
      hostile = {junk};
      why = "random bytes";
    }
  }
  std::shuffle(parts.begin(), parts.end(), rng);
  std::vector<std::string> args{s.name};
  if (s.positional_file && why != "missing file" && why != "random bytes") args.push_back("/nonexistent/robodamp.rec");
  for (const auto& p : parts) args.insert(args.end(), p.begin(), p.end());
  if (why == "value missing") {
    args.insert(args.end(), hostile.begin(), hostile.end());  // last: nothing follows it
  } else {
    const std::size_t at = 1 + below(rng, args.size());
    args.insert(args.begin() + static_cast<std::ptrdiff_t>(at), hostile.begin(), hostile.end());
  }
  if (below(rng, 20) == 0) args[0] = one_of(rng, std::vector<std::string>{"runn", "", "RUN", "bench2", "--bogus"});
  return args;
}

std::string show(const std::vector<std::string>& args) {
  std::string s = "robodamp";
  for (const auto& a : args) s += " '" + a + "'";
  return s;
}

TEST(Fuzz, TenThousandHostileCommandLinesExit2WithAMessage) {
  Rng rng(20261122);
  const auto subs = subcommands();
  std::map<std::string, int> by_kind;
  int failures = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 10000 && failures < 10; ++i) {
    std::string why;
    const auto args = hostile_args(rng, subs, why);
    const ChildResult r = run_in_child(args, 10.0);
    ++by_kind[why];
    const bool ok = r.status == 2 && !r.err.empty();
    if (!ok) ++failures;
    EXPECT_TRUE(ok) << "#" << i << " (" << why << "): " << show(args) << "\n  status " << r.status
                    << (r.status == -1 ? " (hung, killed after 10 s)" : "") << ", stderr: " << r.err;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("[ fuzz cli ] 10000 command lines in %.1f s:", s);
  for (const auto& [k, n] : by_kind) std::printf(" %s %d;", k.c_str(), n);
  std::printf(" all exit 2 with a message: %s\n", failures == 0 ? "yes" : "NO");
}

// --- configuration files ----------------------------------------------------------------------------------

const std::vector<std::string> kBadValues{
    "nan",      ".nan",          ".inf",   "-.inf", "1e308", "-1e308", "0",  "-0",  "1e-320", "99999999999999999999",
    "abc",      "[1, 2]",        "{a: 1}", "''",    "~",     "true",   "-1", "3.5", "\"5\"",  "&anchor 1",
    "*missing", "!!binary AAAA", "0x10"};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t nl = text.find('\n', start);
    out.push_back(text.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  return out;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + '\n';
  return s;
}

std::string mutate(Rng& rng, const std::string& text) {
  auto lines = lines_of(text);
  const std::size_t n = 1 + below(rng, 3);
  for (std::size_t k = 0; k < n && !lines.empty(); ++k) {
    std::string& line = lines[below(rng, lines.size())];
    switch (below(rng, 9)) {
      case 0:
        lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(below(rng, lines.size())));
        break;
      case 1: {
        const std::size_t i = below(rng, lines.size());
        lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i), lines[i]);  // duplicate key
        break;
      }
      case 2:
      case 3: {  // a value swapped for a hostile one
        const std::size_t colon = line.find(": ");
        if (colon != std::string::npos) line = line.substr(0, colon + 2) + one_of(rng, kBadValues);
        break;
      }
      case 4:
        line = (below(rng, 2) ? "  " : "") +
               line.substr(line.empty() ? 0 : below(rng, std::min<std::size_t>(3, line.size()) + 1));
        break;
      case 5: {  // a key renamed
        const std::size_t colon = line.find(':');
        if (colon != std::string::npos) line.insert(colon, "x");
        break;
      }
      case 6: {  // bytes inserted
        std::string junk;
        for (std::size_t i = 1 + below(rng, 6); i > 0; --i)
          junk += one_of(rng, std::vector<std::string>{"\t", ":", "-", "[", "{", "&", "*", "!", "\"", "'", "#", "|",
                                                       ">", "\xc3\xa9", "\x01", "\xff", " ", "%"});
        line.insert(below(rng, line.size() + 1), junk);
        break;
      }
      case 7: {  // a map where a number was
        const std::size_t colon = line.find(": ");
        if (colon != std::string::npos)
          line = line.substr(0, colon + 2) + "\n" + std::string(colon + 2, ' ') + "nested: 1";
        break;
      }
      default: {  // truncated
        std::string all = joined(lines);
        return all.substr(0, below(rng, all.size() + 1));
      }
    }
  }
  return joined(lines);
}

std::string huge(Rng& rng, const std::string& text) {
  switch (below(rng, 3)) {
    case 0:
      return text + "notes: \"" + std::string(4 << 20, 'x') + "\"\n";  // a 4 MiB string
    case 1: {
      std::string s = text + "extra:\n";
      for (int i = 0; i < 200000; ++i) s += "  - " + std::to_string(i) + "\n";  // a 200 000-element list
      return s;
    }
    default:
      return std::string(100000, '[') + std::string(100000, ']');  // deep nesting
  }
}

struct ConfigFuzzCounts {
  int accepted{0}, refused{0}, problems{0};
};

// Every problem names the file and a line in it.
void expect_located(const config::ConfigError& e, const std::string& file, const std::string& text, int& failures) {
  for (const auto& p : e.problems()) {
    const bool ok = p.file == file && p.mark.line >= 1 && !p.message.empty();
    if (!ok && ++failures <= 10) {
      ADD_FAILURE() << "not located at " << file << ":line: " << p.to_string() << "\n--- input ---\n"
                    << text.substr(0, 2000);
    }
  }
}

TEST(Fuzz, TenThousandMutatedConfigurationsAreRefusedWithFileAndLine) {
  Rng rng(4);
  const fs::path dir = scratch("configs");
  fs::create_directories(dir / "presets");
  fs::create_directories(dir / "milling");
  const std::string src = ROBODAMP_SOURCE_DIR;
  for (const auto& e : fs::directory_iterator(src + "/config/presets"))
    fs::copy_file(e.path(), dir / "presets" / e.path().filename(), fs::copy_options::overwrite_existing);
  struct Base {
    std::string text;
    bool milling;
    fs::path path;  // where its mutations are written (relative references resolve as in the tree)
  };
  std::vector<Base> bases;
  for (const char* p : {"horizontal_c1", "horizontal_c2", "horizontal_c3", "vertical_c1"})
    bases.push_back({test::read_file(test::preset(p)), false, dir / "presets" / "fuzz.yaml"});
  bases.push_back({test::read_file(src + "/config/hil_horizontal_c2.yaml"), false, dir / "fuzz_hil.yaml"});
  for (const char* p : {"active_damping_c2", "industrial_robot_aluminium", "orthopaedic_bone"})
    bases.push_back(
        {test::read_file(src + "/config/milling/" + std::string(p) + ".yaml"), true, dir / "milling" / "fuzz.yaml"});
  ConfigFuzzCounts c;
  int failures = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 10000 && failures < 10; ++i) {
    const Base& b = one_of(rng, bases);
    const std::string text = i % 1000 == 999 ? huge(rng, b.text) : mutate(rng, b.text);
    std::ofstream(b.path, std::ios::binary | std::ios::trunc) << text;
    const std::string file = b.path.string();
    try {
      if (b.milling) {
        const auto job = config::load_milling_config(file);
        for (const auto& s : job.structures) (void)milling::Structure(s, false);
      } else {
        const auto cfg = config::load_config_file(file);
        (void)analysis::design_chain(cfg);
        if (!cfg.robot.frfs.empty()) (void)sim::build_plant_model(cfg);
      }
      ++c.accepted;
    } catch (const config::ConfigError& e) {
      ++c.refused;
      c.problems += static_cast<int>(e.problems().size());
      // A file a job refers to (a damping configuration) reports its own file: one that exists, named.
      const std::string other = e.problems().empty() ? std::string() : e.problems().front().file;
      const bool other_file = !other.empty() && other != file && fs::exists(other);
      if (!other_file) expect_located(e, file, text, failures);
    } catch (const std::exception& e) {
      if (++failures <= 10)
        ADD_FAILURE() << "#" << i << ": not a ConfigError: " << e.what() << "\n--- input ---\n" << text.substr(0, 2000);
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "[ fuzz cfg ] 10000 mutated files (%zu bases, 10 huge) in %.1f s: %d accepted, %d refused with %d problems, "
      "every one at file:line: %s\n",
      bases.size(), s, c.accepted, c.refused, c.problems, failures == 0 ? "yes" : "NO");
  // Most mutations break a file (measured: 8066 of 10000); a fuzzer that refused nothing tested nothing.
  EXPECT_GT(c.refused, 5000);
  EXPECT_GE(c.problems, c.refused);
}

// --- recordings ---------------------------------------------------------------------------------------------

TEST(Fuzz, CorruptedRecordingsAreRefusedOrReadNeverCrash) {
  const fs::path good = scratch("good.rec");
  {
    runtime::CellOptions o;
    o.clock = config::ClockKind::kVirtual;
    o.record_path = good.string();
    runtime::Cell cell(config::load_config_file(test::preset("horizontal_c2")), o);
    test::configure(cell);
    (void)cell.run(0.05);
  }
  const std::string bytes = test::read_file(good.string());
  ASSERT_GT(bytes.size(), 16U);
  std::uint32_t header_len = 0;
  std::memcpy(&header_len, bytes.data() + 12, 4);
  Rng rng(7);
  const fs::path bad = scratch("bad.rec");
  int refused = 0, read_ok = 0, replayed = 0, failures = 0;
  for (int i = 0; i < 3000 && failures < 10; ++i) {
    std::string b = bytes;
    switch (below(rng, 7)) {
      case 0:
        b.resize(below(rng, b.size()));
        break;  // truncated anywhere
      case 1:
        for (std::size_t k = 1 + below(rng, 8); k > 0; --k)
          b[below(rng, std::min<std::size_t>(b.size(), 16 + header_len))] ^= static_cast<char>(1 + below(rng, 255));
        break;   // header bytes flipped
      case 2: {  // a lying header length
        const std::uint32_t lie =
            one_of(rng, std::vector<std::uint32_t>{0, 1, header_len - 1, header_len + 1, 0xFFFFFFFFU, 64U << 20,
                                                   static_cast<std::uint32_t>(b.size())});
        std::memcpy(b.data() + 12, &lie, 4);
        break;
      }
      case 3:
        for (std::size_t k = 1 + below(rng, 50); k > 0; --k)
          b[16 + header_len + below(rng, b.size() - 16 - header_len)] = static_cast<char>(below(rng, 256));
        break;   // frame bytes (states, trips and commands out of their enums)
      case 4: {  // the header's JSON rewritten with wrong types
        std::string h = b.substr(16, header_len);
        const auto at =
            h.find(one_of(rng, std::vector<std::string>{"\"rate_hz\":", "\"frame_bytes\":", "\"supervisor\":",
                                                        "\"controller_params\":", "\"sections\":"}));
        if (at != std::string::npos)
          h.insert(h.find(':', at) + 1,
                   one_of(rng, std::vector<std::string>{"\"x\",\"y\":", "null,\"z\":", "[],\"w\":", "-1e999,\"v\":"}));
        const auto len = static_cast<std::uint32_t>(h.size());
        b = b.substr(0, 12) + std::string(reinterpret_cast<const char*>(&len), 4) + h + b.substr(16 + header_len);
        break;
      }
      case 5:
        b += std::string(below(rng, 300), static_cast<char>(below(rng, 256)));
        break;  // trailing garbage
      default: {
        b.resize(below(rng, 4096));
        for (auto& ch : b) ch = static_cast<char>(below(rng, 256));
        if (below(rng, 2)) b.replace(0, std::min<std::size_t>(8, b.size()), "RDAMPREC");
      }
    }
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << b;
    try {
      const rt::Recording r = rt::read_recording(bad.string());
      ++read_ok;
      std::FILE* null = std::fopen("/dev/null", "w");
      rt::write_csv(r, null);
      std::fclose(null);
      (void)rt::replay(r);
      ++replayed;
    } catch (const std::exception& e) {
      ++refused;
      if (std::string(e.what()).empty() && ++failures <= 10) ADD_FAILURE() << "#" << i << ": refused without a message";
    }
  }
  std::printf("[ fuzz rec ] 3000 corrupted recordings: %d refused with a message, %d read (%d replayed to the end)\n",
              refused, read_ok, replayed);
  EXPECT_GT(refused, 0);
  EXPECT_GT(read_ok, 0);
}

}  // namespace
}  // namespace robodamp
