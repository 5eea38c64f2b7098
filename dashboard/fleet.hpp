// The dashboard's view of the DDS domain (docs/dashboard.md): every robodamp cell heard on any topic, told
// apart by the cell name each sample carries; per cell the latest status, machining state, advice, spectrum
// and lobes, the last 30 s of telemetry, when it was last heard, and whether two publishers claim the same
// name. Parameter requests go out named for a cell with this dashboard's own client name, and only the
// replies to that client are taken. Listener threads write; the web server's threads read. Thread-safe.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stop_token>
#include <string>

#include <nlohmann/json.hpp>

#include "config/supervisory_config.hpp"
#include "dds/bridge.hpp"
#include "threads/worker.hpp"

namespace robodamp::dds {
class Participant;
}
namespace eprosima::fastdds::dds {
class DataWriter;
class DataReader;
class DataReaderListener;
}  // namespace eprosima::fastdds::dds

namespace robodamp::dashboard {

struct TelemetryPoint {
  std::uint64_t seq{0};  // per cell, from 1
  double time_s{0.0};
  double accel_rms_mps2{0.0}, accel_mps2{0.0}, command_v{0.0}, command_peak_v{0.0}, gain_ns_per_m{0.0};
  float saturated_fraction{0.0F};
  std::uint8_t state{0}, trip{0};
};

struct FleetCounters {
  std::uint64_t samples{0};          // every valid sample taken
  std::uint64_t bad_cell_names{0};   // samples whose cell name is not a valid one (dropped)
  std::uint64_t foreign_replies{0};  // replies to another client (another dashboard, a robodamp request)
  std::uint64_t requests{0}, replies{0}, reply_timeouts{0};
  std::uint64_t cells_lost{0};       // times a cell went quiet for stale_after_s
  std::uint64_t cells_restarted{0};  // a new status writer after the old one went quiet: the last run's data dropped
  std::uint64_t cells_refused{0};    // samples of a new name beyond the 256 cells kept
};

struct RequestOutcome {
  bool answered{false};  // false: no reply within the timeout
  bool accepted{false};
  std::string reason;
};

class Fleet {
 public:
  // Joins the domain (with dds.security's identity when given). Throws std::runtime_error when it cannot.
  Fleet(const config::DdsConfig& dds, double stale_after_s, std::size_t telemetry_points = 1500);
  ~Fleet();
  Fleet(const Fleet&) = delete;
  Fleet& operator=(const Fleet&) = delete;

  // One tile per cell, by name: state, trip, availability, vibration, speed, depth and limit, chatter,
  // contact ("live", "no contact"), name clash.
  [[nodiscard]] nlohmann::json overview();
  // Everything about one cell and its telemetry after since_seq (nothing when the cell is unknown).
  [[nodiscard]] std::optional<nlohmann::json> detail(const std::string& cell, std::uint64_t since_seq,
                                                     bool with_spectrum_and_lobes = true);
  [[nodiscard]] bool known(const std::string& cell);
  // Blocks up to timeout for a change after `seen` (returns the version now); urgent changes (state, trip,
  // a cell appearing or going quiet) wake it at once, telemetry only when `any` is set.
  std::uint64_t wait(std::uint64_t seen, std::chrono::milliseconds timeout, bool any);
  [[nodiscard]] std::uint64_t version();

  // Sends a parameter request to the cell and waits for its reply (up to timeout_s). who: for the client name.
  [[nodiscard]] RequestOutcome request(const std::string& cell, dds::RequestKind kind, double value,
                                       const std::string& who, double timeout_s);
  [[nodiscard]] FleetCounters counters();
  [[nodiscard]] const std::string& client_name() const { return client_; }
  // Why this dashboard cannot act (its DDS identity's permissions), or empty.
  [[nodiscard]] const std::string& view_only() const { return view_only_; }

 private:
  struct Cell;
  // The status writers heard within stale_after_s: more than one is a name clash (a restarted cell's old
  // writer, quiet since, is not).
  [[nodiscard]] std::size_t live_writers(const Cell& c, std::chrono::steady_clock::time_point now) const;
  template <typename T>
  class Listener;
  class ReplyListener;
  Cell* cell_for(const std::string& name, bool& bad);  // under m_
  void bump(bool urgent);                              // under m_
  void on_telemetry(const void* msg, std::int64_t source_ms);
  void on_status(const void* msg, const std::string& writer, std::int64_t source_ms);
  void on_machining(const void* msg);
  void on_advice(const void* msg);
  void on_spectrum(const void* msg);
  void on_lobes(const void* msg);
  void on_reply(const void* msg);
  void watch_contact(std::stop_token stop);  // thread: marks cells quiet after stale_after_s

  double stale_after_s_;
  std::size_t telemetry_points_;
  std::string client_;
  std::mutex m_;
  std::condition_variable cv_;
  std::map<std::string, std::unique_ptr<Cell>> cells_;
  std::uint64_t version_{0}, urgent_version_{0};
  FleetCounters n_;
  std::uint32_t next_request_id_{1};
  std::map<std::uint32_t, RequestOutcome> replies_;
  bool stop_{false};         // guarded by m_: the waits of the pages and the requests end
  threads::Worker contact_;  // watch_contact (stopped in the destructor before the participant goes)
  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> listeners_;  // outlive the participant
  std::unique_ptr<dds::Participant> participant_;
  eprosima::fastdds::dds::DataWriter* request_writer_{nullptr};
  std::string view_only_;  // why there is no request writer
};

}  // namespace robodamp::dashboard
