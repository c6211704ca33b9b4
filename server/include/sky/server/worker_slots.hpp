// Work that would stall the io thread (POST /api/grib's decode: seconds of
// decoder processes and parsing) on threads of its own, at most a few at a
// time, each handing its result back to the io thread, where every change of
// the weather happens. A member of HttpApi; everything but the work itself
// runs on the io thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stop_token>
#include <thread>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio/io_context.hpp>

namespace sky::server {

class WorkerSlots {
 public:
  // What a work hands back: run on the io thread.
  using Finish = std::function<void()>;
  // The work, on its own thread. `stop` is asked when the slots close; a
  // work that blocks (a child process) should end soon after. What it
  // throws is rethrown on the io thread, from the io_context's run().
  using Work = std::function<Finish(std::stop_token stop)>;

  // slots: works that may run at once, >= 1. `io` outlives this object.
  WorkerSlots(boost::asio::io_context& io, std::size_t slots);
  ~WorkerSlots();  // close()
  WorkerSlots(const WorkerSlots&) = delete;
  WorkerSlots& operator=(const WorkerSlots&) = delete;

  // Starts `work` on a thread of its own; when it returns, its Finish is
  // posted to the io_context and the slot is free once that has run. False,
  // and nothing started, when every slot is taken or after close().
  bool tryStart(Work work);
  // Works started whose Finish has not run yet.
  std::size_t running() const { return threads_.size(); }
  std::size_t slots() const { return slots_; }

  // Asks every running work to stop and waits for its thread. Their
  // Finishes never run (dropped with the io_context's queue). Idempotent.
  void close();

 private:
  boost::asio::io_context& io_;
  std::size_t slots_;
  std::uint64_t nextId_ = 1;
  // False once closed: a Finish posted before then sees it and does
  // nothing. Shared with the posted handlers, which may outlive this object;
  // read and written on the io thread only.
  std::shared_ptr<bool> open_ = std::make_shared<bool>(true);
  // The threads by work; destroying a std::jthread asks it to stop, then
  // joins it.
  std::map<std::uint64_t, std::jthread> threads_;
};

}  // namespace sky::server
