// threads::Worker (threads/worker.hpp): a stop request ends every wait and joins, on every path; notify wakes
// the body once its predicate holds; the thread carries its name. No timing is asserted: each condition is
// waited for with a deadline, so a hang fails the test instead of a slow machine.
#include "threads/worker.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>

namespace {

using namespace std::chrono_literals;
using robodamp::threads::Worker;

// Polls `done` until it holds or 30 s pass (a deadline for a loaded machine, not a timing claim).
template <class Done>
bool eventually(Done done) {
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::yield();
  }
  return true;
}

TEST(Worker, AStopEndsAWaitWhosePredicateNeverHoldsAndJoins) {
  std::mutex m;
  std::atomic<bool> waiting{false}, returned{false}, woke_by_predicate{true};
  Worker w;
  w.start("rd-test-wait", [&](std::stop_token stop) {
    std::unique_lock<std::mutex> lock(m);
    waiting = true;
    woke_by_predicate = w.wait(lock, stop, [] { return false; });
    returned = true;
  });
  ASSERT_TRUE(eventually([&] { return waiting.load(); }));
  EXPECT_TRUE(w.running());
  w.stop();  // joins: the body has returned when stop() does
  EXPECT_TRUE(returned);
  EXPECT_FALSE(woke_by_predicate);
  EXPECT_FALSE(w.running());
  w.stop();  // again: nothing to do
}

TEST(Worker, NotifyWakesTheBodyOnceWhatItWaitsForHolds) {
  std::mutex m;
  int asked = 0, served = 0;
  Worker w;
  w.start("rd-test-serve", [&](std::stop_token stop) {
    std::unique_lock<std::mutex> lock(m);
    while (w.wait(lock, stop, [&] { return asked > served; })) ++served;
  });
  for (int k = 1; k <= 100; ++k) {
    {
      std::lock_guard<std::mutex> lock(m);
      ++asked;
    }
    w.notify();
    ASSERT_TRUE(eventually([&] {
      std::lock_guard<std::mutex> lock(m);
      return served == k;
    })) << "request "
        << k << " not served";
  }
  w.stop();
  EXPECT_EQ(served, 100);
}

// A stop wins over work still queued: a body whose predicate always holds (a long sweep's queue) gets false
// from its wait once a stop is asked, and leaves; the pieces of work it did are the ones before the stop.
TEST(Worker, AStopWinsOverWorkStillQueued) {
  std::mutex m;
  std::atomic<int> done{0};
  std::atomic<bool> asked{false};
  int done_at_stop = -1;
  Worker w;
  w.start("rd-test-queue", [&](std::stop_token stop) {
    std::unique_lock<std::mutex> lock(m);
    while (w.wait(lock, stop, [] { return true; }) &&
           done < 1000) {  // always more to do (bounded: a failure, not a hang)
      lock.unlock();
      ++done;
      while (!asked && done >= 3) std::this_thread::yield();  // hold the third piece until the stop is asked
      lock.lock();
    }
  });
  ASSERT_TRUE(eventually([&] { return done.load() >= 3; }));
  w.request_stop();
  done_at_stop = done.load();
  asked = true;
  w.stop();
  EXPECT_EQ(done.load(), done_at_stop);  // nothing more after the stop, though the queue never emptied
}

TEST(Worker, ATimedWaitAndASleepEndOnTheirTimeoutAndEarlyOnAStop) {
  std::mutex m;
  std::atomic<int> rounds{0};
  std::atomic<bool> slept_through_stop{true};
  Worker w;
  w.start("rd-test-period", [&](std::stop_token stop) {
    std::unique_lock<std::mutex> lock(m);
    while (!stop.stop_requested()) {
      w.wait_for(lock, stop, 1ms, [] { return false; });  // the period: ends on its timeout
      ++rounds;
    }
  });
  ASSERT_TRUE(eventually([&] { return rounds.load() >= 3; }));  // woke by its timeout, again and again
  w.stop();
  Worker sleeper;
  sleeper.start("rd-test-sleep", [&](std::stop_token stop) { slept_through_stop = sleeper.sleep_for(stop, 1h); });
  sleeper.stop();  // an hour's sleep ends at the request
  EXPECT_FALSE(slept_through_stop);
}

TEST(Worker, StartingAgainStopsTheFirstBodyAndTheDestructorJoinsTheSecond) {
  std::atomic<int> ended{0};
  std::atomic<bool> second_started{false};
  {
    Worker w;
    w.start("rd-test-first", [&](std::stop_token stop) {
      while (!stop.stop_requested()) std::this_thread::yield();
      ++ended;
    });
    w.start("rd-test-second", [&](std::stop_token stop) {
      second_started = true;
      while (!stop.stop_requested()) std::this_thread::yield();
      ++ended;
    });
    EXPECT_EQ(ended, 1);  // the first was joined before the second began
    ASSERT_TRUE(eventually([&] { return second_started.load(); }));
  }
  EXPECT_EQ(ended, 2);
}

// The name is the kernel's (what top -H, ps -L and gdb show), cut to its 15 characters.
TEST(Worker, TheThreadCarriesItsName) {
  Worker w;
  w.start("rd-test-a-name-longer-than-15", [&](std::stop_token stop) { w.sleep_for(stop, 1h); });
  const auto named = [] {
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
      std::ifstream comm(task.path() / "comm");
      std::string name;
      std::getline(comm, name);
      if (name == "rd-test-a-name-") return true;
    }
    return false;
  };
  EXPECT_TRUE(eventually(named));
  w.stop();
}

}  // namespace
