#pragma once
// Reads an event source on a thread of its own, a few batches ahead of its consumer, each batch
// prepared there (validated, filtered): reading, decoding and filtering then overlap storage and the
// rounds on a second core, as evldt-lines' storage overlaps its rounds. The batches come out in the
// order read, so a deterministic consumer's output is unchanged. Whatever the source or `prepare`
// throws comes out of next() in its place, after every batch read before it.

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/sources/event_source.hpp"

namespace evldt {

class ReadAhead {
 public:
  struct Item {
    EventBatch batch;               ///< as read, then as `prepare` left it
    EventBatch prepared;            ///< what `prepare` made of it
    std::uint64_t events_read = 0;  ///< the batch's size as read, before `prepare`
    double progress = 0;            ///< the source's, after reading it
  };
  /// Runs on the reading thread for each batch read.
  using Prepare = std::function<void(EventBatch& batch, EventBatch& prepared)>;

  /// Starts reading `source` (which the reading thread alone touches until this is destroyed), at
  /// most `depth` batches ahead.
  ReadAhead(EventSource& source, Prepare prepare, std::size_t depth = 4);
  ~ReadAhead();  ///< stops reading (after the batch being read) and joins
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  /// The next batch, valid until the next call; nullptr at the end. Rethrows what reading threw.
  const Item* next();

 private:
  void read_loop();

  EventSource& source_;
  Prepare prepare_;
  std::vector<Item> ring_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t read_ = 0;      // items filled so far (guarded by mutex_)
  std::size_t taken_ = 0;     // items handed out so far, the last still in use (guarded by mutex_)
  bool ended_ = false;        // the source ended or threw (guarded by mutex_)
  bool stopping_ = false;     // guarded by mutex_
  std::exception_ptr error_;  // guarded by mutex_
  std::thread thread_;
};

}  // namespace evldt
