#include "evldt/sources/read_ahead.hpp"

#include <stdexcept>
#include <utility>

namespace evldt {

ReadAhead::ReadAhead(EventSource& source, Prepare prepare, std::size_t depth)
    : source_(source), prepare_(std::move(prepare)), ring_(depth) {
  // One slot is the consumer's while it works on it, one at least the reader's.
  if (depth < 2) throw std::invalid_argument("ReadAhead: depth must be at least 2");
  thread_ = std::thread([this] { read_loop(); });
}

ReadAhead::~ReadAhead() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void ReadAhead::read_loop() {
  for (;;) {
    std::size_t slot = 0;
    {
      std::unique_lock lock(mutex_);
      // The slot of item `read_` is free once the consumer has moved past the item depth before it
      // (taken_ counts the one in use as taken).
      changed_.wait(lock, [&] { return stopping_ || read_ + 1 < taken_ + ring_.size(); });
      if (stopping_) return;
      slot = read_ % ring_.size();
    }
    Item& item = ring_[slot];
    bool more = false;
    std::exception_ptr error;
    try {
      more = source_.read(item.batch);
      if (more) {
        item.events_read = item.batch.size();
        item.progress = source_.progress();
        prepare_(item.batch, item.prepared);
      }
    } catch (...) {
      error = std::current_exception();
    }
    {
      std::lock_guard lock(mutex_);
      if (more && !error) {
        ++read_;
      } else {
        ended_ = true;
        error_ = error;
      }
    }
    changed_.notify_all();
    if (!more || error) return;
  }
}

const ReadAhead::Item* ReadAhead::next() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return taken_ < read_ || ended_; });
  if (taken_ < read_) {
    const Item* item = &ring_[taken_ % ring_.size()];
    ++taken_;
    changed_.notify_all();
    return item;
  }
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  return nullptr;
}

}  // namespace evldt
