// Who may act on the dashboard (docs/dashboard.md): users from a credentials file (PBKDF2-HMAC-SHA256 with
// a salt per user, OpenSSL), a session token per login (32 random bytes, idle timeout), failed logins
// throttled per user and per address (doubling lock-outs after three failures), and the action log (one
// JSON line per operator action: when, who, from where, which cell, what, the cell's answer).
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace robodamp::dashboard {

enum class Role { kObserver, kOperator };
[[nodiscard]] const char* to_string(Role r);

struct User {
  std::string name;
  Role role{Role::kObserver};
  std::string hash;  // "pbkdf2-sha256$<iterations>$<salt hex>$<key hex>"
};

// "pbkdf2-sha256$..." for a password with a fresh random salt.
[[nodiscard]] std::string hash_password(const std::string& password, int iterations = 200000);
[[nodiscard]] bool verify_password(const std::string& password, const std::string& hash);

// The credentials file: `users: [{name, role, hash}]`. Throws config::ConfigError naming the problem.
[[nodiscard]] std::vector<User> load_users(const std::string& path);
// Adds or replaces a user and writes the file (0600). Throws std::runtime_error on a bad name or I/O.
void save_user(const std::string& path, const User& user);
// Why a user name is refused (empty: fine): 1-32 letters, digits, '-', '_', '.'.
[[nodiscard]] std::string user_name_problem(const std::string& name);

struct Session {
  std::string user;
  Role role{Role::kObserver};
};

enum class LoginOutcome { kOk, kWrong, kThrottled };
struct LoginResult {
  LoginOutcome outcome{LoginOutcome::kWrong};
  std::string token;           // kOk
  Role role{Role::kObserver};  // kOk
  double retry_after_s{0.0};   // kThrottled
};

struct AuthCounters {
  std::uint64_t logins{0}, wrong_passwords{0}, throttled{0}, bad_tokens{0}, logouts{0};
};

class Authenticator {
 public:
  using Clock = std::chrono::steady_clock;
  Authenticator(std::vector<User> users, double session_idle_s);

  // Thread-safe. A wrong user and a wrong password look the same to the caller.
  [[nodiscard]] LoginResult login(const std::string& user, const std::string& password, const std::string& address,
                                  Clock::time_point now = Clock::now());
  [[nodiscard]] std::optional<Session> session(const std::string& token, Clock::time_point now = Clock::now());
  void logout(const std::string& token);
  [[nodiscard]] AuthCounters counters() const;
  [[nodiscard]] bool anyone_may_act() const;

 private:
  struct Failures {
    int count{0};
    Clock::time_point locked_until{};
  };
  [[nodiscard]] double locked_for_s(const std::string& key, Clock::time_point now) const;
  void failed(const std::string& key, Clock::time_point now);

  std::vector<User> users_;
  std::chrono::duration<double> idle_;
  mutable std::mutex m_;
  struct Live {
    Session s;
    Clock::time_point last_used;
  };
  std::map<std::string, Live> sessions_;
  std::map<std::string, Failures> failures_;  // "user:<name>" and "addr:<address>"
  AuthCounters n_;
};

// One operator action, as logged.
struct ActionRecord {
  std::string time_utc;  // ISO 8601
  std::string user, role, address, cell, action;
  double value{0.0};
  bool accepted{false};
  std::string reason;
};

class ActionLog {
 public:
  explicit ActionLog(std::string path);  // empty: memory only
  void append(const ActionRecord& r);    // thread-safe; the file is flushed per line
  [[nodiscard]] std::vector<ActionRecord> recent(std::size_t n) const;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
  mutable std::mutex m_;
  std::vector<ActionRecord> recent_;  // the last 200
};

[[nodiscard]] std::string now_utc_iso8601();

}  // namespace robodamp::dashboard
