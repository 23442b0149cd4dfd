// transport::Wakeup's listener dispatch (the stages' poll on the DDS listener thread, one thread
// wake-up per hop): no notification is lost, the handler never runs twice at once, the node's own
// timer path is serialized with it, runtime::ListenerDispatch hands a listener's exception to the
// node's thread, and a two-participant chain over each vendor's wire answers every cycle in order
// with the answer written from the handler.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "crane/runtime/node_runtime.hpp"
#include "crane/transport/participant.hpp"
#include "crane/transport/topics.hpp"

namespace {

using namespace crane::transport;
namespace tp = crane::transport::topics;
using Clock = std::chrono::steady_clock;

// Counts the handler's calls in flight; the largest count seen must stay 1.
struct Overlap {
  std::atomic<int> in_flight{0};
  std::atomic<int> most{0};
  void enter() {
    const int now = in_flight.fetch_add(1) + 1;
    int seen = most.load();
    while (now > seen && !most.compare_exchange_weak(seen, now)) {}
  }
  void leave() { in_flight.fetch_sub(1); }
};

TEST(Wakeup, EveryNotifyIsFollowedByAHandlerCallThatSeesWhatPrecededIt) {
  constexpr int kThreads = 4;
  constexpr int kNotifies = 20000;
  Wakeup wakeup;
  std::array<std::atomic<int>, kThreads> latest{};  // written before each notify
  std::array<int, kThreads> seen{};                 // what the handler saw last (handler only)
  Overlap overlap;
  std::atomic<long> calls{0};
  wakeup.dispatch_on_notify([&] {
    overlap.enter();
    for (int t = 0; t < kThreads; ++t) seen[t] = latest[t].load();
    calls.fetch_add(1);
    overlap.leave();
  });
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 1; i <= kNotifies; ++i) {
        latest[t].store(i);
        wakeup.notify();
      }
    });
  }
  // The node's timer path meanwhile, under the same exclusion.
  for (int i = 0; i < 200; ++i) {
    wakeup.run_exclusive([&] {
      overlap.enter();
      std::this_thread::sleep_for(std::chrono::microseconds(20));
      overlap.leave();
    });
  }
  for (auto& thread : threads) thread.join();
  wakeup.stop_dispatch();
  EXPECT_EQ(overlap.most.load(), 1) << "the handler ran beside itself or beside run_exclusive";
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(seen[t], kNotifies) << "thread " << t << "'s last notify was lost";
  EXPECT_GE(calls.load(), 1);
  EXPECT_LE(calls.load(), static_cast<long>(kThreads) * kNotifies);
}

TEST(Wakeup, ANotifyDuringAHandlerCallMakesThatCallRepeat) {
  Wakeup wakeup;
  std::atomic<int> calls{0};
  std::atomic<bool> inside{false};
  std::atomic<bool> release{false};
  wakeup.dispatch_on_notify([&] {
    if (calls.fetch_add(1) == 0) {
      inside.store(true);
      while (!release.load()) std::this_thread::yield();
    }
  });
  std::thread listener([&] { wakeup.notify(); });  // the first call, held inside the handler
  while (!inside.load()) std::this_thread::yield();
  wakeup.notify();  // finds the handler running: returns at once, leaving its flag
  EXPECT_EQ(calls.load(), 1);
  release.store(true);
  listener.join();
  EXPECT_EQ(calls.load(), 2) << "the notify made during the first call was not handled";
  wakeup.stop_dispatch();
}

TEST(Wakeup, AfterStopDispatchNotifyWakesTheWaitingThreadAgainAndTheHandlerIsNotCalled) {
  Wakeup wakeup;
  std::atomic<int> calls{0};
  wakeup.dispatch_on_notify([&] { calls.fetch_add(1); });
  wakeup.notify();
  EXPECT_EQ(calls.load(), 1);
  // While dispatching, a notify does not wake wait_until: it returns at its deadline.
  EXPECT_FALSE(wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20)));
  wakeup.stop_dispatch();
  wakeup.notify();
  EXPECT_EQ(calls.load(), 1);
  EXPECT_TRUE(wakeup.wait_until(Clock::now() + std::chrono::seconds(5)));
}

TEST(Wakeup, RunExclusiveHandlesANotifyThatArrivedWhileItRan) {
  Wakeup wakeup;
  std::atomic<int> calls{0};
  wakeup.dispatch_on_notify([&] { calls.fetch_add(1); });
  wakeup.run_exclusive([&] {
    std::thread other([&] { wakeup.notify(); });  // finds the exclusion held: leaves its flag
    other.join();
    EXPECT_EQ(calls.load(), 0);
  });
  EXPECT_EQ(calls.load(), 1) << "the notify made during run_exclusive was not handled after it";
  wakeup.stop_dispatch();
}

// runtime::ListenerDispatch, the stages' and the plant's loop: a poll that throws on a listener
// thread is not called again, and the node's next run() rethrows its exception (the node then stops
// with its message, as when the poll threw on its own thread).
TEST(ListenerDispatch, APollThatThrowsOnAListenerThreadIsRethrownOnTheNodesThread) {
  Wakeup wakeup;
  std::atomic<int> polls{0};
  crane::runtime::ListenerDispatch dispatch(
      wakeup,
      [&] {
        if (polls.fetch_add(1) == 0) throw std::runtime_error("a stage's poll failed");
      },
      true);
  std::thread listener([&] { wakeup.notify(); });  // the poll runs here and throws
  listener.join();
  EXPECT_EQ(polls.load(), 1);
  wakeup.notify();
  EXPECT_EQ(polls.load(), 1) << "a failed poll ran again";
  int timer_work = 0;
  try {
    dispatch.run([&] { ++timer_work; });
    ADD_FAILURE() << "run() did not rethrow the listener's exception";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "a stage's poll failed");
  }
  EXPECT_EQ(timer_work, 0);
  // After the failure, notify() wakes the node's thread again (the dispatch has ended).
  wakeup.notify();
  EXPECT_TRUE(wakeup.wait_until(Clock::now() + std::chrono::seconds(5)));
}

TEST(ListenerDispatch, OnTheNodesThreadOnlyThePollRunsThroughRunAfterAWakeUp) {
  Wakeup wakeup;
  int polls = 0;
  crane::runtime::ListenerDispatch dispatch(wakeup, [&] { ++polls; }, false);
  wakeup.notify();
  EXPECT_EQ(polls, 0) << "--wake thread: a notify ran the poll";
  EXPECT_TRUE(wakeup.wait_until(Clock::now() + std::chrono::seconds(5)));
  int timer_work = 0;
  dispatch.run([&] { ++timer_work; });
  EXPECT_EQ(polls, 1);
  EXPECT_EQ(timer_work, 1);
}

// A lockstep chain of two participants of different vendors: the test writes sensor sample k and
// waits for the estimate of k; the other side answers from its Wakeup's handler on the DDS
// listener thread, as a stage does.
void chain(Vendor driver_vendor, Vendor stage_vendor) {
  constexpr std::uint32_t kCycles = 300;
  ParticipantOptions driver_options;
  driver_options.name = "driver";
  driver_options.domain_id = 62;
  driver_options.vendor = driver_vendor;
  ParticipantOptions stage_options = driver_options;
  stage_options.name = "stage";
  stage_options.vendor = stage_vendor;
  Participant driver(driver_options);
  Participant stage(stage_options);
  Wakeup driver_wakeup;
  Wakeup stage_wakeup;
  auto sensors_out = driver.make_writer<tp::Sensors>();
  auto estimates_in = driver.make_reader<tp::StateEstimate>(&driver_wakeup);
  auto sensors_in = stage.make_reader<tp::Sensors>(&stage_wakeup);
  auto estimates_out = stage.make_writer<tp::StateEstimate>();
  const auto matched_by = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < matched_by &&
         (sensors_out->health().matched_readers == 0 || estimates_out->health().matched_readers == 0 ||
          sensors_in->health().matched_writers == 0 || estimates_in->health().matched_writers == 0)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_GT(estimates_in->health().matched_writers, 0) << "never matched";

  Overlap overlap;
  std::atomic<std::uint32_t> answered{0};
  const auto test_thread = std::this_thread::get_id();
  std::atomic<int> on_other_threads{0};
  stage_wakeup.dispatch_on_notify([&] {
    overlap.enter();
    if (std::this_thread::get_id() != test_thread) on_other_threads.fetch_add(1);
    tp::Sensors::Message sample;
    while (sensors_in->take_next(sample)) {
      tp::StateEstimate::Message estimate;
      estimate.header().seq(sample.header().seq());
      estimates_out->write(estimate);
      answered.fetch_add(1);
    }
    overlap.leave();
  });
  std::uint32_t next = 1;
  const auto until = Clock::now() + std::chrono::seconds(60);
  auto reoffer = Clock::now();
  while (next <= kCycles && Clock::now() < until) {
    if (Clock::now() >= reoffer) {  // offered again after 50 ms: the stream is best-effort
      tp::Sensors::Message sample;
      sample.header().seq(next);
      sensors_out->write(sample);
      reoffer = Clock::now() + std::chrono::milliseconds(50);
    }
    tp::StateEstimate::Message estimate;
    while (estimates_in->take_next(estimate)) {
      if (estimate.header().seq() == next) {
        ++next;
        reoffer = Clock::now();
      }
    }
    driver_wakeup.wait_until(std::min(reoffer, Clock::now() + std::chrono::milliseconds(5)));
  }
  stage_wakeup.stop_dispatch();
  EXPECT_EQ(next, kCycles + 1) << "the chain stalled at cycle " << next;
  EXPECT_GE(answered.load(), kCycles);
  EXPECT_GE(on_other_threads.load(), 1) << "every answer came from the test's own thread, not a listener";
  EXPECT_EQ(overlap.most.load(), 1);
}

TEST(Wakeup, AStageAnswersEveryCycleFromTheListenerThreadFastToCyclone) { chain(Vendor::fast_dds, Vendor::cyclone_dds); }
TEST(Wakeup, AStageAnswersEveryCycleFromTheListenerThreadCycloneToFast) { chain(Vendor::cyclone_dds, Vendor::fast_dds); }

}  // namespace
