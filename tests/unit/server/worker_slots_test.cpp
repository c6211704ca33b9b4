// WorkerSlots (server/include/sky/server/worker_slots.hpp): work on threads
// of its own, at most `slots` at a time, its Finish run on the io thread;
// closing stops the work and drops its Finish; what a work throws comes out
// of the io_context's run().
#include <atomic>
#include <condition_variable>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/post.hpp>

#include "sky/server/worker_slots.hpp"

namespace sky::server {
namespace {

// An io_context run by a thread of its own, as the server's; what a handler
// throws is counted, and the loop runs on (as Server::run does).
class IoThread {
 public:
  IoThread()
      : thread_([this] {
          for (;;) {
            try {
              io.run();
              return;
            } catch (const std::runtime_error&) {
              ++thrown;
            }
          }
        }) {}
  ~IoThread() {
    work_.reset();
    io.stop();
    thread_.join();
  }
  // Runs `f` on the io thread and waits for it.
  template <class F>
  auto on(F f) {
    std::packaged_task<decltype(f())()> task(std::move(f));
    auto result = task.get_future();
    boost::asio::post(io, [&task] { task(); });
    return result.get();
  }
  std::thread::id id() const { return thread_.get_id(); }

  boost::asio::io_context io;
  std::atomic<int> thrown{0};

 private:
  boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_ = boost::asio::make_work_guard(io);
  std::thread thread_;
};

// A latch the test opens.
struct Gate {
  std::mutex m;
  std::condition_variable_any cv;
  bool open = false;
  void release() {
    {
      std::lock_guard lock(m);
      open = true;
    }
    cv.notify_all();
  }
  // Waits until released or `stop` is asked; true when released.
  bool wait(std::stop_token stop) {
    std::unique_lock lock(m);
    return cv.wait(lock, stop, [this] { return open; });
  }
};

TEST(WorkerSlots, FinishRunsOnTheIoThreadAndFreesTheSlot) {
  IoThread io;
  WorkerSlots slots(io.io, 1);
  Gate gate;
  std::promise<std::thread::id> finishedOn;
  std::thread::id workedOn;
  ASSERT_TRUE(io.on([&] {
    return slots.tryStart([&](std::stop_token stop) {
      workedOn = std::this_thread::get_id();
      gate.wait(stop);
      return WorkerSlots::Finish([&] { finishedOn.set_value(std::this_thread::get_id()); });
    });
  }));
  // The one slot is taken until the Finish has run.
  EXPECT_FALSE(io.on([&] { return slots.tryStart([](std::stop_token) { return WorkerSlots::Finish([] {}); }); }));
  gate.release();
  EXPECT_EQ(finishedOn.get_future().get(), io.id());
  EXPECT_NE(workedOn, io.id());
  EXPECT_EQ(io.on([&] { return slots.running(); }), 0u);
  std::promise<void> again;
  EXPECT_TRUE(io.on([&] {
    return slots.tryStart([&](std::stop_token) { return WorkerSlots::Finish([&] { again.set_value(); }); });
  }));
  again.get_future().get();
  io.on([&] { slots.close(); });
}

TEST(WorkerSlots, CloseStopsTheWorkAndDropsItsFinish) {
  IoThread io;
  WorkerSlots slots(io.io, 2);
  Gate gate;  // never released: the work ends because it is asked to stop
  std::atomic<int> stopped{0}, finished{0};
  for (int k = 0; k < 2; ++k)
    ASSERT_TRUE(io.on([&] {
      return slots.tryStart([&](std::stop_token stop) {
        if (!gate.wait(stop)) ++stopped;
        return WorkerSlots::Finish([&] { ++finished; });
      });
    }));
  io.on([&] { slots.close(); });
  EXPECT_EQ(stopped, 2);
  EXPECT_FALSE(io.on([&] { return slots.tryStart([](std::stop_token) { return WorkerSlots::Finish([] {}); }); }));
  io.on([] {});  // the Finishes posted before close() have had their turn
  EXPECT_EQ(finished, 0);
}

TEST(WorkerSlots, WhatAWorkThrowsComesOutOfTheIoLoop) {
  IoThread io;
  WorkerSlots slots(io.io, 1);
  ASSERT_TRUE(io.on([&] {
    return slots.tryStart([](std::stop_token) -> WorkerSlots::Finish { throw std::runtime_error("work failed"); });
  }));
  for (int k = 0; k < 1000 && io.thrown == 0; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(io.thrown, 1);
  EXPECT_EQ(io.on([&] { return slots.running(); }), 0u) << "the slot is free";
  io.on([&] { slots.close(); });
}

}  // namespace
}  // namespace sky::server
