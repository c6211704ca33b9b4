// Work off the io thread, bounded, its result back on the io thread (see
// worker_slots.hpp).
#include "sky/server/worker_slots.hpp"

#include <exception>

#include <boost/asio/post.hpp>

#include "sky/core/assert.hpp"

namespace sky::server {

WorkerSlots::WorkerSlots(boost::asio::io_context& io, std::size_t slots) : io_(io), slots_(slots) {
  SKY_ASSERT(slots >= 1);
}

WorkerSlots::~WorkerSlots() { close(); }

bool WorkerSlots::tryStart(Work work) {
  if (!*open_ || threads_.size() >= slots_) return false;
  const std::uint64_t id = nextId_++;
  // The thread touches nothing of this object but io_, which outlives it;
  // close() joins every thread before this object goes.
  threads_.emplace(id, std::jthread([this, id, open = open_, work = std::move(work)](std::stop_token stop) {
    Finish finish;
    try {
      finish = work(stop);
    } catch (...) {
      finish = [failure = std::current_exception()] { std::rethrow_exception(failure); };
    }
    // Run on the io thread, where `threads_` and `open` are read: so the
    // entry erased here was made before (tryStart runs there too).
    boost::asio::post(io_, [this, id, open, finish = std::move(finish)] {
      if (!*open) return;
      threads_.erase(id);  // joins a thread that has nothing left to do but return
      finish();
    });
  }));
  return true;
}

void WorkerSlots::close() {
  *open_ = false;
  for (auto& [id, thread] : threads_) thread.request_stop();
  threads_.clear();
}

}  // namespace sky::server
