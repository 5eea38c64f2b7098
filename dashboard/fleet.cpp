#include "dashboard/fleet.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <thread>

#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "dds/bridge.hpp"
#include "dds/messages.hpp"
#include "dds/participant.hpp"
#include "rt/supervisor.hpp"

namespace robodamp::dashboard {

using namespace eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

namespace {

constexpr std::size_t kMaxCells = 256;

std::int64_t wall_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

json finite(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }  // JSON has no inf: null

json to_json(const msg::Status& s) {
  return {{"time_s", s.time_s()},
          {"state", s.state().to_string()},
          {"trip", s.trip().to_string()},
          {"trip_description", s.trip_description().to_string()},
          {"backend", s.backend().to_string()},
          {"parameter_set", s.parameter_set()},
          {"gain_ns_per_m", s.gain_ns_per_m()},
          {"max_gain_ns_per_m", s.max_gain_ns_per_m()},
          {"parameter_writes", s.parameter_writes()},
          {"parameter_sets", s.parameter_sets()},
          {"spindle_rpm_max", s.spindle_rpm_max()},
          {"ticks", s.ticks()},
          {"missed_ticks", s.missed_ticks()},
          {"overruns", s.overruns()},
          {"stale_ticks", s.stale_ticks()},
          {"invalid_samples", s.invalid_samples()},
          {"saturated_ticks", s.saturated_ticks()},
          {"ring_drops", s.ring_drops()},
          {"wake_p50_us", s.wake_p50_us()},
          {"wake_p99_us", s.wake_p99_us()},
          {"wake_max_us", s.wake_max_us()},
          {"compute_mean_us", s.compute_mean_us()},
          {"compute_max_us", s.compute_max_us()},
          {"availability_pct", s.availability_pct()},
          {"trips", s.trips()},
          {"back_at_full_gain", s.back_at_full_gain()},
          {"last_trip_s", s.last_trip_s()},
          {"derated", s.derated()},
          {"derated_pct", s.derated_pct()},
          {"wake_histogram", s.wake_histogram()},
          {"compute_histogram", s.compute_histogram()},
          {"histogram_edges_us",
           std::vector<double>(std::begin(dds::kHistogramEdgesUs), std::end(dds::kHistogramEdgesUs))}};
}

json to_json(const msg::Machining& m) {
  return {{"time_s", m.time_s()},
          {"spindle_rpm", m.spindle_rpm()},
          {"tooth_passing_hz", m.tooth_passing_hz()},
          {"depth_mm", m.depth_mm()},
          {"limits_ready", m.limits_ready()},
          {"open_limit_mm", finite(m.open_limit_mm())},
          {"damped_limit_mm", finite(m.damped_limit_mm())},
          {"limit_method", m.limit_method()},
          {"loop_active", m.loop_active()},
          {"limit_mm", finite(m.limit_mm())},
          {"depth_warning", m.depth_warning()},
          {"depth_measured", m.depth_measured()},
          {"indicator_valid", m.indicator_valid()},
          {"once_per_rev_ratio", m.once_per_rev_ratio()},
          {"nonharmonic_share", m.nonharmonic_share()},
          {"chatter_hz", m.chatter_hz()},
          {"chatter", m.chatter()},
          {"cutting", dds::cutting_name(m.cutting())},
          {"cutting_reason", m.cutting_reason()},
          {"pose_deg", m.pose_deg()},
          {"limits_pose_deg", m.limits_pose_deg()},
          {"mode_spread_pct", m.mode_spread_pct()},
          {"nearest_measured_deg", m.nearest_measured_deg()}};
}

json to_json(const msg::Advice& a) {
  json options = json::array();
  for (std::size_t i = 0; i < a.option_rpm().size() && i < a.option_limit_mm().size(); ++i)
    options.push_back({{"rpm", a.option_rpm()[i]}, {"limit_mm", finite(a.option_limit_mm()[i])}});
  return {{"seq", a.seq()},
          {"time_s", a.time_s()},
          {"trigger", a.trigger()},
          {"spindle_rpm", a.spindle_rpm()},
          {"depth_mm", a.depth_mm()},
          {"damped", a.damped()},
          {"chatter_hz", a.chatter_hz()},
          {"limit_now_mm", finite(a.limit_now_mm())},
          {"method", a.method()},
          {"found", a.found()},
          {"advised_rpm", a.advised_rpm()},
          {"advised_limit_mm", finite(a.advised_limit_mm())},
          {"margin", finite(a.margin())},
          {"options", options},
          {"best_rpm", a.best_rpm()},
          {"best_limit_mm", finite(a.best_limit_mm())},
          {"reason", a.reason()},
          {"rpm_min", a.rpm_min()},
          {"rpm_max", a.rpm_max()},
          {"pose_deg", a.pose_deg()},
          {"poses_ahead", a.poses_ahead()},
          {"limiting_pose_deg", a.limiting_pose_deg()},
          {"status", a.status()},
          {"status_reason", a.status_reason()}};
}

json to_json(const msg::Spectrum& s) {
  json asd = json::array();
  for (const float v : s.accel_asd()) asd.push_back(finite(v));
  return {{"time_s", s.time_s()}, {"bin_hz", s.bin_hz()},   {"record_s", s.record_s()},
          {"accel_asd", asd},     {"mode_hz", s.mode_hz()}, {"tooth_passing_hz", s.tooth_passing_hz()}};
}

json to_json(const msg::Lobes& l) {
  json open = json::array(), damped = json::array();
  for (const double v : l.open_limit_mm()) open.push_back(finite(v));
  for (const double v : l.damped_limit_mm()) damped.push_back(finite(v));
  return {{"time_s", l.time_s()},    {"parameter_set", l.parameter_set()}, {"gain_ns_per_m", l.gain_ns_per_m()},
          {"method", l.method()},    {"depth_mm", l.depth_mm()},           {"rpm", l.rpm()},
          {"open_limit_mm", open},   {"damped_limit_mm", damped},          {"speed_scheduled", l.speed_scheduled()},
          {"pose_deg", l.pose_deg()}};
}

}  // namespace

struct Fleet::Cell {
  std::string name;
  Clock::time_point heard{};
  bool live{true};
  std::map<std::string, Clock::time_point> status_writers;  // writer GUID: last heard (two live: a name clash)
  json status, machining, advice, spectrum, lobes;
  std::int64_t status_source_ms{0}, status_received_ms{0};
  std::int64_t state_source_ms{0};  // the writer's wall clock when the state or trip shown last changed
  std::deque<TelemetryPoint> telemetry;
  std::uint64_t seq{0};
  std::uint64_t restarts{0};  // runs heard after the first (a new status writer once the old one was quiet)
  double active_s{0.0}, last_time_s{-1.0};
  std::uint8_t state{255}, trip{255};
};

template <typename T>
class Fleet::Listener : public DataReaderListener {
 public:
  using Handler = std::function<void(const T&, const SampleInfo&)>;
  explicit Listener(Handler h) : h_(std::move(h)) {}
  void on_data_available(DataReader* r) override {
    T v;
    SampleInfo info;
    while (r->take_next_sample(&v, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) h_(v, info);
  }

 private:
  Handler h_;
};

Fleet::Fleet(const config::DdsConfig& dds, double stale_after_s, std::size_t telemetry_points)
    : stale_after_s_(stale_after_s), telemetry_points_(telemetry_points) {
  char host[64] = {};
  (void)gethostname(host, sizeof host - 1);
  client_ = "dashboard-" + std::string(host).substr(0, 24) + "-" + std::to_string(getpid());
  auto add = [this]<typename T>(std::function<void(const T&, const SampleInfo&)> h) {
    listeners_.push_back(std::make_unique<Listener<T>>(std::move(h)));
    return listeners_.back().get();
  };
  auto* telemetry = add(std::function<void(const msg::Telemetry&, const SampleInfo&)>(
      [this](const msg::Telemetry& v, const SampleInfo& i) {
        on_telemetry(&v, i.source_timestamp.to_ns() / 1000000);
      }));
  auto* status =
      add(std::function<void(const msg::Status&, const SampleInfo&)>([this](const msg::Status& v, const SampleInfo& i) {
        std::ostringstream guid;
        guid << i.sample_identity.writer_guid();
        on_status(&v, guid.str(), i.source_timestamp.to_ns() / 1000000);
      }));
  auto* machining = add(std::function<void(const msg::Machining&, const SampleInfo&)>(
      [this](const msg::Machining& v, const SampleInfo&) { on_machining(&v); }));
  auto* advice = add(std::function<void(const msg::Advice&, const SampleInfo&)>(
      [this](const msg::Advice& v, const SampleInfo&) { on_advice(&v); }));
  auto* spectrum = add(std::function<void(const msg::Spectrum&, const SampleInfo&)>(
      [this](const msg::Spectrum& v, const SampleInfo&) { on_spectrum(&v); }));
  auto* lobes = add(std::function<void(const msg::Lobes&, const SampleInfo&)>(
      [this](const msg::Lobes& v, const SampleInfo&) { on_lobes(&v); }));
  auto* reply = add(std::function<void(const msg::ParameterReply&, const SampleInfo&)>(
      [this](const msg::ParameterReply& v, const SampleInfo&) { on_reply(&v); }));
  participant_ = std::make_unique<dds::Participant>(dds.domain_id, dds.transport, "robodamp dashboard", dds.security);
  participant_->reader(dds::TopicKind::kTelemetry, telemetry);
  participant_->reader(dds::TopicKind::kStatus, status);
  participant_->reader(dds::TopicKind::kMachining, machining);
  participant_->reader(dds::TopicKind::kAdvice, advice);
  participant_->reader(dds::TopicKind::kSpectrum, spectrum);
  participant_->reader(dds::TopicKind::kLobes, lobes);
  try {  // an observer identity may neither read replies nor write requests: the dashboard then only shows
    participant_->reader(dds::TopicKind::kReply, reply);
    request_writer_ = participant_->writer(dds::TopicKind::kRequest);
  } catch (const std::runtime_error& e) {
    if (!dds.security) throw;
    request_writer_ = nullptr;
    view_only_ = std::string("this dashboard's DDS identity may not write parameter requests (") + e.what() + ")";
  }
  contact_.start("rd-fleet-watch", [this](std::stop_token stop) { watch_contact(stop); });
}

Fleet::~Fleet() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;  // the pages' and requests' waits return
  }
  cv_.notify_all();
  contact_.stop();
  participant_.reset();  // no listener is called after this
}

Fleet::Cell* Fleet::cell_for(const std::string& name, bool& bad) {
  bad = !config::cell_name_problem(name).empty();
  if (bad) {
    ++n_.bad_cell_names;
    return nullptr;
  }
  if (cells_.size() >= kMaxCells && cells_.count(name) == 0) {  // bounded: a flood of names cannot grow memory
    ++n_.cells_refused;
    return nullptr;
  }
  auto& c = cells_[name];
  if (!c) {
    c = std::make_unique<Cell>();
    c->name = name;
    ++urgent_version_;  // a new tile
  }
  ++n_.samples;
  if (!c->live) ++urgent_version_;  // back in contact
  c->heard = Clock::now();
  c->live = true;
  return c.get();
}

void Fleet::bump(bool urgent) {
  ++version_;
  if (urgent) ++urgent_version_;
  cv_.notify_all();
}

void Fleet::on_telemetry(const void* p, std::int64_t source_ms) {
  const auto& t = *static_cast<const msg::Telemetry*>(p);
  std::lock_guard<std::mutex> lock(m_);
  bool bad = false;
  Cell* c = cell_for(t.cell().to_string(), bad);
  if (c == nullptr) return;
  if (c->last_time_s >= 0.0 && c->state == static_cast<std::uint8_t>(rt::State::kActive) && t.time_s() > c->last_time_s)
    c->active_s += t.time_s() - c->last_time_s;
  if (t.time_s() < c->last_time_s) c->active_s = 0.0;  // the cell restarted
  c->last_time_s = t.time_s();
  const bool urgent = t.state() != c->state || t.trip() != c->trip;
  if (urgent) c->state_source_ms = source_ms;
  c->state = t.state(), c->trip = t.trip();
  c->telemetry.push_back({++c->seq, t.time_s(), t.accel_rms_mps2(), t.accel_mps2(), t.command_v(), t.command_peak_v(),
                          t.gain_ns_per_m(), t.saturated_fraction(), t.state(), t.trip()});
  if (c->telemetry.size() > telemetry_points_) c->telemetry.pop_front();
  bump(urgent);
}

void Fleet::on_status(const void* p, const std::string& writer, std::int64_t source_ms) {
  const auto& s = *static_cast<const msg::Status*>(p);
  std::lock_guard<std::mutex> lock(m_);
  bool bad = false;
  Cell* c = cell_for(s.cell().to_string(), bad);
  if (c == nullptr) return;
  const bool urgent =
      c->status.is_null() || c->status["state"] != s.state().to_string() || c->status["trip"] != s.trip().to_string();
  const bool news =
      rt::to_string(static_cast<rt::State>(c->state)) != s.state().to_string() ||
      rt::to_string(static_cast<rt::Trip>(c->trip)) != s.trip().to_string();  // before the telemetry said it
  if (urgent && news) c->state_source_ms = source_ms;
  // A writer not heard before while none is live: the cell restarted. What its last run published (the
  // advice, the machining state, the spectrum, the lobes, the telemetry) is not about this run: dropped, so
  // that no screen shows, and no operator follows, an old run's advice.
  const auto now = Clock::now();
  if (!c->status.is_null() && c->status_writers.count(writer) == 0 && live_writers(*c, now) == 0) {
    c->machining = c->advice = c->spectrum = c->lobes = json();
    c->telemetry.clear();
    ++n_.cells_restarted;
    ++c->restarts;
  }
  c->status = to_json(s);
  c->status_writers[writer] = now;
  c->status_source_ms = source_ms;
  c->status_received_ms = wall_ms();
  bump(urgent);
}

void Fleet::on_machining(const void* p) {
  const auto& m = *static_cast<const msg::Machining*>(p);
  std::lock_guard<std::mutex> lock(m_);
  bool bad = false;
  if (Cell* c = cell_for(m.cell().to_string(), bad)) c->machining = to_json(m), bump(false);
}

void Fleet::on_advice(const void* p) {
  const auto& a = *static_cast<const msg::Advice*>(p);
  std::lock_guard<std::mutex> lock(m_);
  bool bad = false;
  if (Cell* c = cell_for(a.cell().to_string(), bad)) c->advice = to_json(a), bump(true);
}

void Fleet::on_spectrum(const void* p) {
  const auto& s = *static_cast<const msg::Spectrum*>(p);
  std::lock_guard<std::mutex> lock(m_);
  bool bad = false;
  if (Cell* c = cell_for(s.cell().to_string(), bad)) c->spectrum = to_json(s), bump(false);
}

void Fleet::on_lobes(const void* p) {
  const auto& l = *static_cast<const msg::Lobes*>(p);
  std::lock_guard<std::mutex> lock(m_);
  bool bad = false;
  if (Cell* c = cell_for(l.cell().to_string(), bad)) c->lobes = to_json(l), bump(false);
}

void Fleet::on_reply(const void* p) {
  const auto& r = *static_cast<const msg::ParameterReply*>(p);
  std::lock_guard<std::mutex> lock(m_);
  const auto it = replies_.find(r.request_id());
  if (r.client().to_string().rfind(client_ + "/", 0) != 0 || it == replies_.end()) {  // "<client>/<user>": another's
    ++n_.foreign_replies;
    return;
  }
  ++n_.replies;
  it->second = {true, r.accepted(), r.reason().to_string()};
  cv_.notify_all();
}

void Fleet::watch_contact(std::stop_token stop) {
  while (contact_.sleep_for(stop, std::chrono::milliseconds(100))) {
    std::lock_guard<std::mutex> lock(m_);
    const auto now = Clock::now();
    for (auto& [name, c] : cells_) {
      if (c->live && now - c->heard > std::chrono::duration<double>(stale_after_s_)) {
        c->live = false;
        ++n_.cells_lost;
        bump(true);
      }
      for (auto it = c->status_writers.begin(); it != c->status_writers.end();)  // writers gone quiet
        it = now - it->second > std::chrono::duration<double>(stale_after_s_ * 5.0) ? c->status_writers.erase(it)
                                                                                    : std::next(it);
    }
  }
}

std::size_t Fleet::live_writers(const Cell& c, Clock::time_point now) const {
  return static_cast<std::size_t>(std::count_if(c.status_writers.begin(), c.status_writers.end(), [&](const auto& w) {
    return now - w.second <= std::chrono::duration<double>(stale_after_s_);
  }));
}

json Fleet::overview() {
  std::lock_guard<std::mutex> lock(m_);
  const auto now = Clock::now();
  json tiles = json::array();
  for (const auto& [name, c] : cells_) {
    json t = {{"cell", name},
              {"live", c->live},
              {"quiet_s", std::chrono::duration<double>(now - c->heard).count()},
              {"publishers", live_writers(*c, now)},
              {"active_s", c->active_s},
              {"state_source_ms", c->state_source_ms}};
    if (!c->status.is_null()) {
      t["state"] = c->status["state"];  // without telemetry, the status's word
      t["trip"] = c->status["trip"];
      t["trip_description"] = c->status["trip_description"];
      t["availability_pct"] = c->status["availability_pct"];
      t["trips"] = c->status["trips"];
      t["derated"] = c->status["derated"];
      t["derated_pct"] = c->status["derated_pct"];
      t["backend"] = c->status["backend"];
      t["status_source_ms"] = c->status_source_ms;
      t["status_received_ms"] = c->status_received_ms;
    }
    if (!c->telemetry.empty()) {  // the telemetry is newer than the last periodic status
      const auto& p = c->telemetry.back();
      t["state"] = rt::to_string(static_cast<rt::State>(p.state));
      t["trip"] = rt::to_string(static_cast<rt::Trip>(p.trip));
      t["accel_rms_mps2"] = p.accel_rms_mps2;
      t["command_peak_v"] = p.command_peak_v;
      t["time_s"] = p.time_s;
    }
    if (!c->machining.is_null()) t["machining"] = c->machining;
    if (!c->advice.is_null())
      t["advice"] = {
          {"seq", c->advice["seq"]}, {"found", c->advice["found"]}, {"advised_rpm", c->advice["advised_rpm"]}};
    tiles.push_back(std::move(t));
  }
  return tiles;
}

std::optional<json> Fleet::detail(const std::string& cell, std::uint64_t since_seq, bool with_spectrum_and_lobes) {
  std::lock_guard<std::mutex> lock(m_);
  const auto it = cells_.find(cell);
  if (it == cells_.end()) return std::nullopt;
  const Cell& c = *it->second;
  json tel = {{"time_s", json::array()},    {"accel_mps2", json::array()},    {"accel_rms_mps2", json::array()},
              {"command_v", json::array()}, {"gain_ns_per_m", json::array()}, {"saturated_fraction", json::array()}};
  for (const auto& p : c.telemetry) {
    if (p.seq <= since_seq) continue;
    tel["time_s"].push_back(p.time_s);
    tel["accel_mps2"].push_back(finite(p.accel_mps2));
    tel["accel_rms_mps2"].push_back(finite(p.accel_rms_mps2));
    tel["command_v"].push_back(finite(p.command_v));
    tel["gain_ns_per_m"].push_back(finite(p.gain_ns_per_m));
    tel["saturated_fraction"].push_back(p.saturated_fraction);
  }
  tel["last_seq"] = c.seq;
  json out = {{"cell", cell},           {"live", c.live},
              {"status", c.status},     {"machining", c.machining},
              {"advice", c.advice},     {"telemetry", tel},
              {"active_s", c.active_s}, {"publishers", live_writers(c, Clock::now())},
              {"restarts", c.restarts}};
  if (with_spectrum_and_lobes) out["spectrum"] = c.spectrum, out["lobes"] = c.lobes;
  return out;
}

bool Fleet::known(const std::string& cell) {
  std::lock_guard<std::mutex> lock(m_);
  return cells_.count(cell) != 0;
}

std::uint64_t Fleet::version() {
  std::lock_guard<std::mutex> lock(m_);
  return version_;
}

std::uint64_t Fleet::wait(std::uint64_t seen, std::chrono::milliseconds timeout, bool any) {
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait_for(lock, timeout, [&] { return stop_ || (any ? version_ : urgent_version_) > seen; });
  return any ? version_ : urgent_version_;
}

RequestOutcome Fleet::request(const std::string& cell, dds::RequestKind kind, double value, const std::string& who,
                              double timeout_s) {
  if (request_writer_ == nullptr) return {true, false, view_only_};
  std::uint32_t id = 0;
  {
    std::lock_guard<std::mutex> lock(m_);
    id = next_request_id_++;
    replies_[id] = {};
    ++n_.requests;
  }
  msg::ParameterRequest req;
  req.cell(cell);
  req.client((client_ + "/" + who).substr(0, 64));
  req.request_id(id);
  req.kind(static_cast<std::uint8_t>(kind));
  req.value(value);
  request_writer_->write(&req);
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return stop_ || replies_[id].answered; });
  RequestOutcome out = replies_[id];
  replies_.erase(id);
  if (!out.answered)
    ++n_.reply_timeouts, out.reason = "no reply from cell " + cell + " within " + std::to_string(timeout_s) + " s";
  return out;
}

FleetCounters Fleet::counters() {
  std::lock_guard<std::mutex> lock(m_);
  return n_;
}

}  // namespace robodamp::dashboard
