#include "dashboard/auth.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ctime>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/rand.h>
#include <yaml-cpp/yaml.h>

#include "config/config.hpp"
#include "config/supervisory_config.hpp"

namespace robodamp::dashboard {

namespace {

constexpr int kFreeFailures = 3;  // then locked out: 1 s, 2 s, 4 s ... per further failure
constexpr double kMaxLockout_s = 300.0;

std::string hex(const unsigned char* p, std::size_t n) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < n; ++i) out += digits[p[i] >> 4], out += digits[p[i] & 15];
  return out;
}

std::optional<std::vector<unsigned char>> unhex(const std::string& s) {
  if (s.size() % 2 != 0) return std::nullopt;
  std::vector<unsigned char> out;
  for (std::size_t i = 0; i < s.size(); i += 2) {
    const auto v = [](char c) {
      return std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
    };
    const int hi = v(s[i]), lo = v(s[i + 1]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out.push_back(static_cast<unsigned char>(hi * 16 + lo));
  }
  return out;
}

std::vector<unsigned char> random_bytes(std::size_t n) {
  std::vector<unsigned char> b(n);
  if (RAND_bytes(b.data(), static_cast<int>(n)) != 1) throw std::runtime_error("OpenSSL RAND_bytes failed");
  return b;
}

std::vector<unsigned char> pbkdf2(const std::string& password, const std::vector<unsigned char>& salt, int iterations) {
  std::vector<unsigned char> key(32);
  if (PKCS5_PBKDF2_HMAC(password.data(), static_cast<int>(password.size()), salt.data(), static_cast<int>(salt.size()),
                        iterations, EVP_sha256(), static_cast<int>(key.size()), key.data()) != 1)
    throw std::runtime_error("OpenSSL PKCS5_PBKDF2_HMAC failed");
  return key;
}

[[noreturn]] void refuse(const std::string& path, const std::string& key, const std::string& why) {
  throw config::ConfigError({config::Problem{path, {}, key, why}});
}

}  // namespace

const char* to_string(Role r) { return r == Role::kOperator ? "operator" : "observer"; }

std::string user_name_problem(const std::string& name) { return config::name_problem(name, "user name", 32); }

std::string hash_password(const std::string& password, int iterations) {
  const auto salt = random_bytes(16);
  const auto key = pbkdf2(password, salt, iterations);
  return "pbkdf2-sha256$" + std::to_string(iterations) + "$" + hex(salt.data(), salt.size()) + "$" +
         hex(key.data(), key.size());
}

bool verify_password(const std::string& password, const std::string& hash) {
  std::vector<std::string> parts;
  std::stringstream ss(hash);
  for (std::string p; std::getline(ss, p, '$');) parts.push_back(p);
  if (parts.size() != 4 || parts[0] != "pbkdf2-sha256") return false;
  int iterations = 0;
  try {
    iterations = std::stoi(parts[1]);
  } catch (const std::exception&) {
    return false;
  }
  const auto salt = unhex(parts[2]), key = unhex(parts[3]);
  if (iterations < 1000 || iterations > 10000000 || !salt || !key || key->empty()) return false;
  const auto got = pbkdf2(password, *salt, iterations);
  return got.size() == key->size() && CRYPTO_memcmp(got.data(), key->data(), got.size()) == 0;
}

std::vector<User> load_users(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    refuse(path, "(file)", std::string("cannot be read as YAML: ") + e.what());
  }
  if (!root["users"] || !root["users"].IsSequence())
    refuse(path, "users", "missing (required: a list of {name, role, hash})");
  std::vector<User> out;
  for (std::size_t i = 0; i < root["users"].size(); ++i) {
    const YAML::Node u = root["users"][i];
    const std::string key = "users[" + std::to_string(i) + "]";
    if (!u.IsMap() || !u["name"] || !u["role"] || !u["hash"]) refuse(path, key, "needs name, role and hash");
    User user{u["name"].as<std::string>(), Role::kObserver, u["hash"].as<std::string>()};
    if (const auto p = user_name_problem(user.name); !p.empty())
      refuse(path, key + ".name", "= '" + user.name + "' " + p);
    const std::string role = u["role"].as<std::string>();
    if (role != "operator" && role != "observer")
      refuse(path, key + ".role", "= '" + role + "': allowed operator or observer");
    user.role = role == "operator" ? Role::kOperator : Role::kObserver;
    if (user.hash.rfind("pbkdf2-sha256$", 0) != 0)
      refuse(path, key + ".hash", "is not a pbkdf2-sha256 hash (robodamp dashboard-user writes one)");
    if (std::any_of(out.begin(), out.end(), [&](const User& o) { return o.name == user.name; }))
      refuse(path, key + ".name", "= '" + user.name + "' appears twice");
    out.push_back(std::move(user));
  }
  return out;
}

void save_user(const std::string& path, const User& user) {
  if (const auto p = user_name_problem(user.name); !p.empty())
    throw std::runtime_error("user name '" + user.name + "' " + p);
  std::vector<User> users;
  std::ifstream probe(path);
  if (probe.good()) users = load_users(path);
  const auto it = std::find_if(users.begin(), users.end(), [&](const User& u) { return u.name == user.name; });
  if (it != users.end())
    *it = user;
  else
    users.push_back(user);
  YAML::Emitter e;
  e << YAML::BeginMap << YAML::Key << "users" << YAML::Value << YAML::BeginSeq;
  for (const auto& u : users)
    e << YAML::BeginMap << YAML::Key << "name" << YAML::Value << u.name << YAML::Key << "role" << YAML::Value
      << to_string(u.role) << YAML::Key << "hash" << YAML::Value << u.hash << YAML::EndMap;
  e << YAML::EndSeq << YAML::EndMap;
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << "# robodamp dashboard users (robodamp dashboard-user writes this file; PBKDF2-HMAC-SHA256 hashes)\n"
        << e.c_str() << '\n';
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  ::chmod(tmp.c_str(), 0600);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error("cannot replace " + path);
}

Authenticator::Authenticator(std::vector<User> users, double session_idle_s)
    : users_(std::move(users)), idle_(session_idle_s) {}

bool Authenticator::anyone_may_act() const {
  return std::any_of(users_.begin(), users_.end(), [](const User& u) { return u.role == Role::kOperator; });
}

double Authenticator::locked_for_s(const std::string& key, Clock::time_point now) const {
  const auto it = failures_.find(key);
  if (it == failures_.end() || it->second.locked_until <= now) return 0.0;
  return std::chrono::duration<double>(it->second.locked_until - now).count();
}

void Authenticator::failed(const std::string& key, Clock::time_point now) {
  Failures& f = failures_[key];
  if (++f.count > kFreeFailures) {
    const double s = std::min(kMaxLockout_s, std::pow(2.0, f.count - kFreeFailures - 1));
    f.locked_until = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
}

LoginResult Authenticator::login(const std::string& user, const std::string& password, const std::string& address,
                                 Clock::time_point now) {
  const std::string by_user = "user:" + user, by_addr = "addr:" + address;
  {
    std::lock_guard<std::mutex> lock(m_);
    const double wait = std::max(locked_for_s(by_user, now), locked_for_s(by_addr, now));
    if (wait > 0.0) {
      ++n_.throttled;
      return {LoginOutcome::kThrottled, {}, Role::kObserver, wait};
    }
  }
  const auto it = std::find_if(users_.begin(), users_.end(), [&](const User& u) { return u.name == user; });
  // The hash is computed for an unknown user too: the time does not tell which part was wrong.
  const bool ok = verify_password(
      password, it != users_.end() ? it->hash
                                   : std::string("pbkdf2-sha256$200000$00000000000000000000000000000000$"
                                                 "0000000000000000000000000000000000000000000000000000000000000000"));
  std::lock_guard<std::mutex> lock(m_);
  if (!ok || it == users_.end()) {
    ++n_.wrong_passwords;
    failed(by_user, now);
    failed(by_addr, now);
    return {LoginOutcome::kWrong, {}, Role::kObserver, 0.0};
  }
  failures_.erase(by_user);
  failures_.erase(by_addr);
  const auto bytes = random_bytes(32);
  std::string token = hex(bytes.data(), bytes.size());
  sessions_[token] = {{it->name, it->role}, now};
  ++n_.logins;
  return {LoginOutcome::kOk, token, it->role, 0.0};
}

std::optional<Session> Authenticator::session(const std::string& token, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(m_);
  for (auto it = sessions_.begin(); it != sessions_.end();)  // expire the idle ones
    it = now - it->second.last_used > idle_ ? sessions_.erase(it) : std::next(it);
  const auto it = sessions_.find(token);
  if (it == sessions_.end()) {
    if (!token.empty()) ++n_.bad_tokens;
    return std::nullopt;
  }
  it->second.last_used = now;
  return it->second.s;
}

void Authenticator::logout(const std::string& token) {
  std::lock_guard<std::mutex> lock(m_);
  if (sessions_.erase(token) > 0) ++n_.logouts;
}

AuthCounters Authenticator::counters() const {
  std::lock_guard<std::mutex> lock(m_);
  return n_;
}

std::string now_utc_iso8601() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[40];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03lldZ", b, static_cast<long long>(ms));
  return out;
}

ActionLog::ActionLog(std::string path) : path_(std::move(path)) {}

void ActionLog::append(const ActionRecord& r) {
  const nlohmann::json j = {{"time", r.time_utc},   {"user", r.user},         {"role", r.role},
                            {"address", r.address}, {"cell", r.cell},         {"action", r.action},
                            {"value", r.value},     {"accepted", r.accepted}, {"reason", r.reason}};
  std::lock_guard<std::mutex> lock(m_);
  if (!path_.empty()) {
    std::ofstream out(path_, std::ios::app);
    out << j.dump() << '\n';
  }
  recent_.push_back(r);
  if (recent_.size() > 200) recent_.erase(recent_.begin());
}

std::vector<ActionRecord> ActionLog::recent(std::size_t n) const {
  std::lock_guard<std::mutex> lock(m_);
  const std::size_t from = recent_.size() > n ? recent_.size() - n : 0;
  return {recent_.begin() + static_cast<std::ptrdiff_t>(from), recent_.end()};
}

}  // namespace robodamp::dashboard
