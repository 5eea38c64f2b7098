#include "dds/bridge.hpp"

#include <algorithm>
#include <cmath>

#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include "dds/participant.hpp"
#include "dds/messages.hpp"

namespace robodamp::dds {

using namespace eprosima::fastdds::dds;

namespace {
// The 10000 one-microsecond bins summed into kHistogramEdgesUs's bins (overflow in the last).
std::vector<std::uint64_t> coarse_histogram(const rt::TimingHistogram& h) {
  std::vector<std::uint64_t> out(kHistogramBins, 0);
  std::size_t bin = 0;
  for (std::size_t us = 0; us < rt::TimingHistogram::kBins; ++us) {
    while (bin + 1 < kHistogramBins && static_cast<double>(us) >= kHistogramEdgesUs[bin + 1]) ++bin;
    out[bin] += h.bin(us);
  }
  out.back() += h.overflow();
  return out;
}
}  // namespace

class Bridge::RequestListener : public DataReaderListener {
 public:
  explicit RequestListener(Bridge& b) : b_(b) {}
  void on_data_available(DataReader* reader) override {
    msg::ParameterRequest req;
    SampleInfo info;
    while (reader->take_next_sample(&req, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (req.cell() != b_.src_.cell) {  // for another cell on the domain: that one answers
        ++b_.n_other_cells_;
        continue;
      }
      const std::optional<RequestKind> kind = req.kind() == msg::SET_GAIN ? RequestKind::kSetGain
                                              : req.kind() == msg::SELECT_PARAMETER_SET
                                                  ? RequestKind::kSelectParameterSet
                                              : req.kind() == msg::SET_SPINDLE_RPM ? RequestKind::kSetSpindleRpm
                                              : req.kind() == msg::ENABLE          ? RequestKind::kEnable
                                              : req.kind() == msg::RESET_FAULT     ? RequestKind::kResetFault
                                                                                   : std::optional<RequestKind>{};
      const Decision d = kind ? b_.decide(*kind, req.value())
                              : b_.refuse("kind = " + std::to_string(req.kind()) +
                                          " is not a request kind: allowed 0 to 4 "
                                          "(dds/robodamp.idl)");
      msg::ParameterReply reply;
      reply.cell(b_.src_.cell);
      reply.client(req.client());
      reply.request_id(req.request_id());
      reply.accepted(d.accepted);
      reply.reason(d.reason.substr(0, 255));
      b_.reply_writer_->write(&reply);
    }
  }

 private:
  Bridge& b_;
};

// dds.joint_states: each valid message's names and positions to the cell (a ROS 2 driver's joint states).
class Bridge::JointStateListener : public DataReaderListener {
 public:
  explicit JointStateListener(Bridge& b) : b_(b) {}
  void on_data_available(DataReader* reader) override {
    msg::JointState js;
    SampleInfo info;
    while (reader->take_next_sample(&js, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) b_.src_.joint_state(js.name(), js.position());
  }

 private:
  Bridge& b_;
};

// dds.path_ahead: each valid trajectory's joint names and points to the cell (a robot program's next poses).
class Bridge::TrajectoryListener : public DataReaderListener {
 public:
  explicit TrajectoryListener(Bridge& b) : b_(b) {}
  void on_data_available(DataReader* reader) override {
    msg::JointTrajectory t;
    SampleInfo info;
    while (reader->take_next_sample(&t, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::vector<TrajectoryPoint> points;
      points.reserve(t.points().size());
      for (const msg::JointTrajectoryPoint& p : t.points())
        points.push_back({p.positions(), p.time_from_start().sec() + 1e-9 * p.time_from_start().nanosec()});
      b_.src_.trajectory(t.joint_names(), points);
    }
  }

 private:
  Bridge& b_;
};

Bridge::Bridge(const config::DdsConfig& cfg, double loop_rate_hz, const std::string& config_source,
               BridgeSources sources)
    : cfg_(cfg), source_(config_source), src_(std::move(sources)), availability_(loop_rate_hz, src_.gain_ramp_s) {
  window_ticks_ =
      std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::llround(loop_rate_hz / cfg.telemetry_rate_hz)));
  participant_ = std::make_unique<Participant>(cfg.domain_id, cfg.transport, "robodamp loop", cfg.security);
  telemetry_writer_ = participant_->writer(TopicKind::kTelemetry);
  status_writer_ = participant_->writer(TopicKind::kStatus);
  reply_writer_ = participant_->writer(TopicKind::kReply);
  if (src_.machining) machining_writer_ = participant_->writer(TopicKind::kMachining);
  if (src_.advice) advice_writer_ = participant_->writer(TopicKind::kAdvice);
  if (src_.spectrum) spectrum_writer_ = participant_->writer(TopicKind::kSpectrum);
  if (src_.lobes) lobes_writer_ = participant_->writer(TopicKind::kLobes);
  listener_ = std::make_unique<RequestListener>(*this);
  participant_->reader(TopicKind::kRequest, listener_.get());
}

Bridge::~Bridge() {
  stop();
  participant_.reset();  // the listener outlives the reader
}

Decision Bridge::refuse(std::string reason) {
  ++n_requests_;
  ++n_refused_;
  return {false, std::move(reason)};
}

Decision Bridge::decide(RequestKind kind, double value) {
  ++n_requests_;
  Decision d;
  bool running = false;
  {
    // The request reader listens from the bridge's construction, while the cell still builds the loop its
    // requests go to (ThreadSanitizer found one reaching Cell::handle_request then): they reach the cell
    // only between start() and stop(), ordered after what the cell built by this lock.
    std::lock_guard<std::mutex> lock(m_);
    running = running_;
  }
  if (!running)
    d = {false, "the cell is not running (starting or stopped): try again once it runs"};
  else if (!cfg_.parameter_writes)
    d = {false, "parameter writes are off: dds.parameter_writes is false in " + source_};
  else
    d = src_.handle(kind, value);
  if (!d.accepted) ++n_refused_;
  return d;
}

void Bridge::on_frame(const rt::TelemetryFrame& f) {
  sum_sq_ += f.accel_mps2 * f.accel_mps2;
  peak_v_ = std::max(peak_v_, std::abs(f.command_v));
  wake_max_us_ = std::max(wake_max_us_, f.wake_latency_us);
  if (f.flags & rt::kFlagSaturated) ++saturated_in_window_;
  bool changed = false;
  {
    std::lock_guard<std::mutex> lock(m_);
    last_ = f;
    have_frame_ = true;
    availability_.on_frame(f);
    if (f.wake_latency_us > 0.0F || f.compute_us > 0.0F) {
      wake_.record(static_cast<std::int64_t>(f.wake_latency_us * 1e3F));
      compute_.record(static_cast<std::int64_t>(f.compute_us * 1e3F));
    }
    changed = f.state != published_state_ || f.trip != published_trip_;
  }
  if (++in_window_ >= window_ticks_) {
    msg::Telemetry t;
    t.cell(src_.cell);
    t.tick(f.tick);
    t.time_s(f.time_s);
    t.accel_rms_mps2(std::sqrt(sum_sq_ / static_cast<double>(in_window_)));
    t.accel_mps2(f.accel_mps2);
    t.filtered_mps(f.filtered_mps);
    t.command_v(f.command_v);
    t.command_peak_v(peak_v_);
    t.gain_ns_per_m(f.gain_ns_per_m);
    t.saturated_fraction(static_cast<float>(saturated_in_window_) / static_cast<float>(in_window_));
    t.wake_latency_max_us(wake_max_us_);
    t.state(f.state);
    t.trip(f.trip);
    if (telemetry_writer_->write(&t)) ++n_telemetry_;
    in_window_ = 0, sum_sq_ = 0.0, peak_v_ = 0.0, saturated_in_window_ = 0, wake_max_us_ = 0.0F;
  }
  if (changed) publish_status();
}

void Bridge::publish_status() {
  msg::Status s;
  s.cell(src_.cell);
  {
    std::lock_guard<std::mutex> lock(m_);
    const auto& f = last_;
    s.tick(f.tick);
    s.time_s(f.time_s);
    s.state(rt::to_string(static_cast<rt::State>(f.state)));
    s.trip(rt::to_string(static_cast<rt::Trip>(f.trip)));
    s.trip_description(std::string(rt::describe(static_cast<rt::Trip>(f.trip))).substr(0, 159));
    s.gain_ns_per_m(f.gain_ns_per_m);
    s.ticks(have_frame_ ? f.tick + 1 - f.missed_ticks : 0);
    s.missed_ticks(f.missed_ticks);
    s.overruns(f.overruns);
    s.stale_ticks(f.stale_ticks);
    s.invalid_samples(f.invalid_samples);
    s.saturated_ticks(f.saturated_ticks);
    s.ring_drops(f.ring_drops);
    s.wake_p50_us(static_cast<float>(wake_.percentile_us(0.5)));
    s.wake_p99_us(static_cast<float>(wake_.percentile_us(0.99)));
    s.wake_max_us(static_cast<float>(wake_.max_us()));
    s.compute_mean_us(static_cast<float>(compute_.mean_us()));
    s.compute_max_us(static_cast<float>(compute_.max_us()));
    const rt::Availability& a = availability_.result();
    s.availability_pct(static_cast<float>(100.0 * a.share()));
    s.trips(static_cast<std::uint32_t>(a.trips_total));
    std::uint32_t back = 0;
    for (const auto& t : a.trips) back += t.full_gain_again_s >= 0.0 ? 1U : 0U;
    s.back_at_full_gain(back);
    s.last_trip_s(a.trips.empty() ? -1.0 : a.trips.back().trip_s);
    s.derated((f.flags & rt::kFlagDerated) != 0);
    s.derated_pct(static_cast<float>(a.asked_s > 0.0 ? 100.0 * a.derated_s / a.asked_s : 0.0));
    s.wake_histogram(coarse_histogram(wake_));
    s.compute_histogram(coarse_histogram(compute_));
    published_state_ = f.state;
    published_trip_ = f.trip;
  }
  s.backend(src_.backend.substr(0, 63));
  s.parameter_set(static_cast<std::uint32_t>(src_.parameter_set ? src_.parameter_set() : 0));
  s.max_gain_ns_per_m(src_.gain_limit_ns_per_m ? src_.gain_limit_ns_per_m() : 0.0);
  s.parameter_writes(cfg_.parameter_writes);
  s.parameter_sets(static_cast<std::uint32_t>(src_.parameter_sets ? src_.parameter_sets() : 1));
  s.spindle_rpm_max(src_.spindle_rpm_max);
  if (status_writer_->write(&s)) ++n_status_;
}

namespace {

// A pose on a bounded sequence<double, 16>: a robot has fewer joints.
std::vector<double> first16(const std::vector<double>& v) {
  return {v.begin(), v.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(16, v.size()))};
}

}  // namespace

void Bridge::publish_machining() {
  if (machining_writer_ == nullptr) return;
  const MachiningSample m = src_.machining();
  msg::Machining out;
  out.cell(src_.cell);
  out.tick(m.tick);
  out.time_s(m.time_s);
  out.spindle_rpm(m.spindle_rpm);
  out.tooth_passing_hz(m.tooth_passing_hz);
  out.depth_mm(m.depth_mm);
  out.depth_measured(m.depth_measured);
  out.limits_ready(m.limits_ready);
  out.open_limit_mm(m.open_limit_mm);
  out.damped_limit_mm(m.damped_limit_mm);
  out.limit_method(m.limit_method);
  out.loop_active(m.loop_active);
  out.limit_mm(m.limit_mm);
  out.depth_warning(m.depth_warning);
  out.indicator_valid(m.indicator_valid);
  out.once_per_rev_ratio(static_cast<float>(m.once_per_rev_ratio));
  out.nonharmonic_share(static_cast<float>(m.nonharmonic_share));
  out.chatter_hz(static_cast<float>(m.chatter_hz));
  out.chatter(m.chatter);
  out.cutting(m.cutting);
  out.cutting_reason(m.cutting_reason);
  out.pose_deg(first16(m.pose_deg));
  out.limits_pose_deg(first16(m.limits_pose_deg));
  out.mode_spread_pct(m.mode_spread_pct);
  out.nearest_measured_deg(m.nearest_measured_deg);
  if (machining_writer_->write(&out)) ++n_machining_;
}

void Bridge::publish_advice() {
  if (advice_writer_ == nullptr) return;
  const std::optional<AdviceSample> a = src_.advice();
  if (!a || (a->seq == published_advice_ && a->status == published_advice_status_)) return;
  msg::Advice out;
  out.cell(src_.cell);
  out.seq(a->seq);
  out.time_s(a->time_s);
  out.trigger(a->trigger);
  out.spindle_rpm(a->spindle_rpm);
  out.depth_mm(a->depth_mm);
  out.damped(a->damped);
  out.chatter_hz(a->chatter_hz);
  out.limit_now_mm(a->limit_now_mm);
  out.method(a->method);
  out.found(a->found);
  out.advised_rpm(a->advised_rpm);
  out.advised_limit_mm(a->advised_limit_mm);
  out.margin(a->margin);
  const std::size_t n = std::min<std::size_t>(8, std::min(a->option_rpm.size(), a->option_limit_mm.size()));
  out.option_rpm(std::vector<double>(a->option_rpm.begin(), a->option_rpm.begin() + static_cast<std::ptrdiff_t>(n)));
  out.option_limit_mm(
      std::vector<double>(a->option_limit_mm.begin(), a->option_limit_mm.begin() + static_cast<std::ptrdiff_t>(n)));
  out.best_rpm(a->best_rpm);
  out.best_limit_mm(a->best_limit_mm);
  out.reason(a->reason);
  out.rpm_min(a->rpm_min);
  out.rpm_max(a->rpm_max);
  out.pose_deg(first16(a->pose_deg));
  out.poses_ahead(a->poses_ahead);
  out.limiting_pose_deg(first16(a->limiting_pose_deg));
  out.status(a->status);
  out.status_reason(a->status_reason);
  if (advice_writer_->write(&out)) {
    ++n_advice_;
    published_advice_ = a->seq;
    published_advice_status_ = a->status;
  }
}

void Bridge::publish_spectrum() {
  if (spectrum_writer_ == nullptr) return;
  const std::optional<SpectrumSample> sp = src_.spectrum();
  if (!sp) return;
  msg::Spectrum out;
  out.cell(src_.cell);
  out.tick(sp->tick);
  out.time_s(sp->time_s);
  out.bin_hz(sp->bin_hz);
  out.record_s(sp->record_s);
  out.accel_asd(std::vector<float>(
      sp->accel_asd.begin(),
      sp->accel_asd.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(1024, sp->accel_asd.size()))));
  out.mode_hz(std::vector<float>(
      sp->mode_hz.begin(),
      sp->mode_hz.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(16, sp->mode_hz.size()))));
  out.tooth_passing_hz(sp->tooth_passing_hz);
  if (spectrum_writer_->write(&out)) ++n_spectrum_;
}

void Bridge::publish_lobes() {
  if (lobes_writer_ == nullptr) return;
  const std::optional<LobesSample> l = src_.lobes();
  if (!l) return;
  const std::size_t n = std::min<std::size_t>({256, l->rpm.size(), l->open_limit_mm.size(), l->damped_limit_mm.size()});
  auto first = [n](const std::vector<double>& v) {
    return std::vector<double>(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n));
  };
  msg::Lobes out;
  out.cell(src_.cell);
  out.time_s(l->time_s);
  out.parameter_set(static_cast<std::uint32_t>(l->parameter_set));
  out.gain_ns_per_m(l->gain_ns_per_m);
  out.method(l->method.substr(0, 47));
  out.depth_mm(l->depth_mm);
  out.rpm(first(l->rpm));
  out.open_limit_mm(first(l->open_limit_mm));
  out.damped_limit_mm(first(l->damped_limit_mm));
  out.speed_scheduled(l->speed_scheduled);
  out.pose_deg(first16(l->pose_deg));
  if (lobes_writer_->write(&out)) ++n_lobes_;
}

void Bridge::start() {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (running_) return;
    running_ = true;
  }
  // The joint states from start on (the cell's loop is there to take the pose's region).
  if (cfg_.joint_states && src_.joint_state && !joint_state_listener_) {
    joint_state_listener_ = std::make_unique<JointStateListener>(*this);
    participant_->joint_state_reader(cfg_.joint_states->topic, joint_state_listener_.get());
  }
  if (cfg_.path_ahead && src_.trajectory && !trajectory_listener_) {
    trajectory_listener_ = std::make_unique<TrajectoryListener>(*this);
    participant_->trajectory_reader(cfg_.path_ahead->topic, trajectory_listener_.get());
  }
  status_.start("rd-dds-status", [this](std::stop_token stop) {
    const auto period = std::chrono::duration<double>(1.0 / cfg_.status_rate_hz);
    for (bool more = true; more;) {  // once more after the stop: the state the cell stopped in
      more = status_.sleep_for(stop, period);
      publish_status();
      publish_machining();
      publish_advice();
      publish_spectrum();
      publish_lobes();
      if (src_.joint_state_check) src_.joint_state_check();
    }
  });
}

void Bridge::stop() {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (!running_) return;
    running_ = false;
  }
  status_.stop();
}

BridgeCounters Bridge::counters() const {
  return {n_telemetry_.load(), n_status_.load(),   n_requests_.load(), n_refused_.load(),    n_machining_.load(),
          n_advice_.load(),    n_spectrum_.load(), n_lobes_.load(),    n_other_cells_.load()};
}

}  // namespace robodamp::dds
